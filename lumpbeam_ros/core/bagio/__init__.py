"""rosbag2/MCAP reading and writing, and message <-> numpy conversion (no ROS imports).

Writing::

    with BagWriter('out/drop') as bag:
        bag.write_pose('/tip_pose', t, x, z, pitch)      # PoseStamped in beam_base
        bag.write_float('/tip_load', t, 4.5)             # Float64, kg

Reading::

    poses = read_tip_poses('out/drop')                # TipSeries: t, x, z, pitch, frame_id
    load = read_load_events('out/drop').changes()
"""

from lumpbeam_ros.core.bagio.convert import CameraInfoData, Status
from lumpbeam_ros.core.bagio.reader import BagReader, RawMessage, open_bag
from lumpbeam_ros.core.bagio.repair import RepairSummary, reindex, repair_bag
from lumpbeam_ros.core.bagio.series import (
    ImageFrame,
    PointSeries,
    iter_images,
    read_accelerations,
    read_camera_info,
    read_diagnostics,
    read_floats,
    read_load_events,
    read_points,
    read_tip_poses,
)
from lumpbeam_ros.core.bagio.tipseries import LoadSeries, TipSeries
from lumpbeam_ros.core.bagio.writer import BagWriter

__all__ = [
    'BagReader',
    'BagWriter',
    'CameraInfoData',
    'ImageFrame',
    'LoadSeries',
    'PointSeries',
    'RawMessage',
    'RepairSummary',
    'Status',
    'TipSeries',
    'iter_images',
    'open_bag',
    'read_accelerations',
    'read_camera_info',
    'read_diagnostics',
    'read_floats',
    'read_load_events',
    'read_points',
    'read_tip_poses',
    'reindex',
    'repair_bag',
]
