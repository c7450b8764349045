"""The optional packages of ``lumpbeam`` and the one line that names a missing one.

``pip install lumpbeam_ros`` installs what the offline commands need (``reproduce``,
``synth``, ``analyze``, ``diagnose``, ``compare``); the rest comes with an extra of setup.py:
``[vision]`` (OpenCV, for ``track`` and the camera node), ``[ros]`` (rclpy and the message
packages, for ``record``, ``play``, ``demo`` and the nodes), ``[plots]`` (matplotlib, for
``--plots``), ``[campaign]`` (Dask and pyarrow, for ``campaign``), ``[view]`` (the Foxglove
SDK, for ``view``) or ``[all]``.
"""

from __future__ import annotations

from typing import NamedTuple


class OptionalPackage(NamedTuple):
    """A package that only some commands need.

    Attributes:
        name: What a user knows it as.
        extra: The extra of ``lumpbeam_ros`` that installs it.
    """

    name: str
    extra: str


_VISION = OptionalPackage('OpenCV', 'vision')
_ROS = OptionalPackage('ROS 2 (rclpy)', 'ros')
_PLOTS = OptionalPackage('matplotlib', 'plots')
_CAMPAIGN = OptionalPackage('Dask and pyarrow', 'campaign')
_VIEW = OptionalPackage('the Foxglove SDK', 'view')

#: Top-level import name -> the package that provides it.
OPTIONAL_MODULES: dict[str, OptionalPackage] = {
    'cv2': _VISION,
    'matplotlib': _PLOTS,
    'rclpy': _ROS,
    'rosidl_runtime_py': _ROS,
    'builtin_interfaces': _ROS,
    'std_msgs': _ROS,
    'geometry_msgs': _ROS,
    'sensor_msgs': _ROS,
    'diagnostic_msgs': _ROS,
    'rosgraph_msgs': _ROS,
    'rcl_interfaces': _ROS,
    'visualization_msgs': _ROS,
    'dask': _CAMPAIGN,
    'distributed': _CAMPAIGN,
    'pyarrow': _CAMPAIGN,
    'foxglove': _VIEW,
}


def missing_package_message(command: str, error: ModuleNotFoundError) -> str | None:
    """The line that tells which optional package a command lacks and how to install it.

    Args:
        command: The subcommand that failed, e.g. ``'track'``.
        error: The import error it raised.

    Returns:
        E.g. ``lumpbeam track needs OpenCV: pip install 'lumpbeam_ros[vision]'``, or ``None``
        when the missing module is not an optional package (a broken install or a bug).
    """
    package = OPTIONAL_MODULES.get((error.name or '').partition('.')[0])
    if package is None:
        return None
    return f"lumpbeam {command} needs {package.name}: pip install 'lumpbeam_ros[{package.extra}]'"
