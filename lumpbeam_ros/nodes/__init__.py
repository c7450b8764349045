"""The ROS 2 adapters: nodes that translate messages into core calls, and what they need.

One module per node (``*_node.py``) and for the recorder and player; :mod:`~.params`: each
node's declared parameters; :mod:`~.realtime`: real-time scheduling; :mod:`~.sent_time`: dating
messages that carry no stamp; :mod:`~.ros_domain`: private domains; :mod:`~.foxglove_server`:
the live view over Foxglove's WebSocket.
"""

__all__ = [
    'camera_node',
    'counts',
    'diagnosis_node',
    'endpoints',
    'foxglove_server',
    'identifier_node',
    'launch_file',
    'lifecycle',
    'msgtypes',
    'player',
    'realtime',
    'recorder',
    'ros_domain',
    'ros_parameters',
    'scripts',
    'sent_time',
    'shaper_node',
    'simulator_node',
    'trajectory_messages',
    'params',
]
