"""The graph's names, declared once: topics, their message types, frames, statuses, nodes.

``doc/interfaces.md`` ("Topics", "Nodes") states them to users; the code takes them from here
and nowhere else. ROS-free: the bag tools, the demo and the nodes share it.

Topic names are absolute, as bags store them and as the default graph (no namespace) shows
them. Nodes create their publishers and subscriptions with the :func:`relative` name, so that a
namespace (``--ros-args -r __ns:=/beam_a``) or a remap (``-r tip_pose:=/other``) moves them:
``/tip_pose`` becomes ``/beam_a/tip_pose``. ``/clock`` stays absolute (rclpy's time source
listens there), and so does ``/diagnostics`` (read graph-wide by diagnostic aggregators; its
statuses carry a ``hardware_id``). Each topic's QoS profile is
:func:`lumpbeam_ros.core.bagio.qos.default_profile` of its name and type; a node's endpoints take
it through :mod:`lumpbeam_ros.nodes.endpoints`, which also lets parameters override it.
"""

from __future__ import annotations

# -- frames -----------------------------------------------------------------------------------

#: The beam's frame: origin at the clamp, x toward the tip, z up (doc/interfaces.md, "Frames").
BASE_FRAME = 'beam_base'
#: The optical frame of the synthetic camera's images.
CAMERA_FRAME = 'camera'
#: The frame of an accelerometer or IMU at the tip (``/tip_imu``).
TIP_FRAME = 'tip'

# -- message types ----------------------------------------------------------------------------

POSE_STAMPED = 'geometry_msgs/msg/PoseStamped'
POSE_WITH_COVARIANCE = 'geometry_msgs/msg/PoseWithCovarianceStamped'
POINT_STAMPED = 'geometry_msgs/msg/PointStamped'
FLOAT64 = 'std_msgs/msg/Float64'
DIAGNOSTIC_ARRAY = 'diagnostic_msgs/msg/DiagnosticArray'
IMAGE_TYPE = 'sensor_msgs/msg/Image'
COMPRESSED_IMAGE_TYPE = 'sensor_msgs/msg/CompressedImage'
CAMERA_INFO_TYPE = 'sensor_msgs/msg/CameraInfo'
CLOCK_TYPE = 'rosgraph_msgs/msg/Clock'
MARKER_ARRAY = 'visualization_msgs/msg/MarkerArray'
JOINT_STATE_TYPE = 'sensor_msgs/msg/JointState'
JOINT_TRAJECTORY_TYPE = 'trajectory_msgs/msg/JointTrajectory'
IMU_TYPE = 'sensor_msgs/msg/Imu'

# -- topics (absolute: the default graph's and the bags' names) -------------------------------

IMAGE = '/camera/image_raw'
CAMERA_INFO = '/camera/camera_info'
COMPRESSED_IMAGE = '/camera/image_raw/compressed'
TIP_POSE = '/tip_pose'
TIP_POSE_COVARIANCE = '/tip_pose_covariance'
TIP_LOAD = '/tip_load'
#: The tip's acceleration (m/s^2, in the header's frame): an accelerometer or IMU at the tip.
TIP_IMU = '/tip_imu'
BEAM_PARAMS = '/beam_params'
TIP_POSE_PREDICTED = '/tip_pose_predicted'
CLOCK = '/clock'
TRACKER_POINT = '/tracker/point'
BEAM_MARKERS = '/beam_markers'
MODEL_DISCREPANCY = '/model_discrepancy'
DIAGNOSTICS = '/diagnostics'
TIP_POSE_TRUTH = '/tip_pose_truth'
#: An arm's joint angles (rad): its encoders, or the commanded angles of a simulated arm.
JOINT_STATES = '/joint_states'
JOINT_TRAJECTORY = '/joint_trajectory'
JOINT_TRAJECTORY_SHAPED = '/joint_trajectory_shaped'
#: The identified arm: its links (or payload) fitted to every ring-down so far.
ARM_PARAMS = '/arm_params'

#: Every topic of the interface with its message type.
TOPIC_TYPES: dict[str, str] = {
    IMAGE: IMAGE_TYPE,
    CAMERA_INFO: CAMERA_INFO_TYPE,
    COMPRESSED_IMAGE: COMPRESSED_IMAGE_TYPE,
    TIP_POSE: POSE_STAMPED,
    TIP_POSE_COVARIANCE: POSE_WITH_COVARIANCE,
    TIP_LOAD: FLOAT64,
    TIP_IMU: IMU_TYPE,
    BEAM_PARAMS: DIAGNOSTIC_ARRAY,
    TIP_POSE_PREDICTED: POSE_STAMPED,
    CLOCK: CLOCK_TYPE,
    TRACKER_POINT: POINT_STAMPED,
    BEAM_MARKERS: MARKER_ARRAY,
    MODEL_DISCREPANCY: DIAGNOSTIC_ARRAY,
    DIAGNOSTICS: DIAGNOSTIC_ARRAY,
    TIP_POSE_TRUTH: POSE_STAMPED,
    JOINT_STATES: JOINT_STATE_TYPE,
    JOINT_TRAJECTORY: JOINT_TRAJECTORY_TYPE,
    JOINT_TRAJECTORY_SHAPED: JOINT_TRAJECTORY_TYPE,
    ARM_PARAMS: DIAGNOSTIC_ARRAY,
}

#: Topics that stay absolute in a namespace: the graph-wide ones.
GLOBAL_TOPICS = (CLOCK, DIAGNOSTICS)

# -- diagnostic statuses ----------------------------------------------------------------------

#: The status on ``/beam_params``.
IDENTIFIER_STATUS = 'lumpbeam/identifier'
#: The status on ``/arm_params``.
ARM_STATUS = 'lumpbeam/arm'
#: The status on ``/model_discrepancy``.
DIAGNOSIS_STATUS = 'lumpbeam/diagnosis'
#: The camera node's status on ``/diagnostics``.
CAMERA_STATUS = 'lumpbeam/camera'

# -- node names -------------------------------------------------------------------------------

CAMERA_NODE = 'camera_node'
IDENTIFIER_NODE = 'identifier_node'
SIMULATOR_NODE = 'simulator_node'
DIAGNOSIS_NODE = 'diagnosis_node'
SHAPER_NODE = 'shaper_node'
PLAYER_NODE = 'lumpbeam_player'
RECORDER_NODE = 'lumpbeam_recorder'
#: The nodes, each also the name of its executable (``setup.py``'s console scripts).
NODE_NAMES = (CAMERA_NODE, IDENTIFIER_NODE, SIMULATOR_NODE, DIAGNOSIS_NODE, SHAPER_NODE)


def node_topic(topic: str) -> str:
    """The name a node subscribes or publishes ``topic`` by.

    Relative (resolved in the node's namespace, open to remaps) except for
    :data:`GLOBAL_TOPICS`; without a namespace both resolve to ``topic`` itself.

    Args:
        topic: An absolute topic name, e.g. ``'/tip_pose'``.

    Returns:
        E.g. ``'tip_pose'``, or ``'/clock'``.

    Raises:
        ValueError: ``topic`` is not absolute.
    """
    if not topic.startswith('/'):
        raise ValueError(f'not an absolute topic name: {topic!r}')
    return topic if topic in GLOBAL_TOPICS else topic[1:]


def in_namespace(topic: str, namespace: str) -> str:
    """Where a node in ``namespace`` finds ``topic`` on the graph.

    Args:
        topic: An absolute topic name, e.g. ``'/tip_pose'``.
        namespace: E.g. ``'/beam_a'``; ``''`` or ``'/'`` for none.

    Returns:
        E.g. ``'/beam_a/tip_pose'`` (``/clock`` stays ``'/clock'``).
    """
    name = node_topic(topic)
    if name.startswith('/'):
        return name
    return f'{namespace.rstrip("/")}/{name}'


#: The pose rate of the camera the package is built around, and of synthetic and predicted
#: poses by default, Hz.
POSE_RATE_HZ = 180.0
#: The rate of /beam_markers by default (the simulator node, synthetic bags), Hz.
MARKERS_RATE_HZ = 30.0
