"""Where the configured checkerboard hangs in ``beam_base``, as the viewers draw it."""

from __future__ import annotations

from scipy.spatial.transform import Rotation

from lumpbeam_ros.core.vision.config import CameraConfig
from lumpbeam_ros.core.viz.markers import BoardPlacement


def board_placement(config: CameraConfig) -> BoardPlacement:
    """Where a camera configuration's checkerboard hangs (``board.xyz_m``, ``board.rpy_rad``).

    Args:
        config: The camera configuration (``config/camera.yaml``).

    Returns:
        The board's centre, orientation and printed size.
    """
    board = config.rig.board
    pose = config.rig.base_board
    outline = board.outline_m
    x, y, z, w = Rotation.from_matrix(pose.rotation).as_quat()
    return BoardPlacement(
        center=tuple(float(v) for v in pose.translation),  # type: ignore[arg-type]
        orientation=(float(x), float(y), float(z), float(w)),
        width_m=float(outline[:, 0].max() - outline[:, 0].min()),
        height_m=float(outline[:, 1].max() - outline[:, 1].min()),
    )
