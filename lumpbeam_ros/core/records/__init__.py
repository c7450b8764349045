"""A lab's measured records: LabVIEW, CSV, NumPy and MATLAB files read, and turned into bags.

- :mod:`~.labfile`: one channel of a file and its time (:class:`~.labfile.LabRecord`);
- :mod:`~.units`: the quantities, their units and axes;
- :mod:`~.to_bag`: a record written as ``/tip_pose`` or ``/tip_imu`` in SI units.
"""

__all__ = ['units', 'labfile', 'to_bag']
