"""lumpbeam_ros: live tip tracking and online identification of flexible beams.

The core (``model``, ``vision``, ``ident``, ``diagnose``, ``bagio``, ``plots``) is plain Python
and never imports ROS; ``nodes`` and ``cli`` are thin layers that translate messages and
command-line arguments into calls on that core.
"""

__version__ = '0.1.0'
