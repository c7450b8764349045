import ast
from pathlib import Path

import pytest

from lumpbeam_ros.apps.cli.dependencies import OPTIONAL_MODULES, missing_package_message

SETUP_PY = Path(__file__).resolve().parents[3] / 'setup.py'


def setup_extras() -> dict[str, list[str]]:
    """The ``EXTRAS`` literal of setup.py (``all`` is computed from it)."""
    for node in ast.parse(SETUP_PY.read_text()).body:
        if isinstance(node, ast.Assign) and getattr(node.targets[0], 'id', '') == 'EXTRAS':
            return ast.literal_eval(node.value)
    raise AssertionError('setup.py has no EXTRAS')


def test_every_hint_names_an_extra_of_setup_py():
    extras = setup_extras()
    assert {package.extra for package in OPTIONAL_MODULES.values()} == set(extras)


@pytest.mark.parametrize(
    ('module', 'command', 'line'),
    [
        ('cv2', 'track', "lumpbeam track needs OpenCV: pip install 'lumpbeam_ros[vision]'"),
        ('cv2.aruco', 'track', "lumpbeam track needs OpenCV: pip install 'lumpbeam_ros[vision]'"),
        (
            'rclpy.node',
            'play',
            "lumpbeam play needs ROS 2 (rclpy): pip install 'lumpbeam_ros[ros]'",
        ),
        (
            'sensor_msgs.msg',
            'demo',
            "lumpbeam demo needs ROS 2 (rclpy): pip install 'lumpbeam_ros[ros]'",
        ),
        (
            'matplotlib',
            'analyze',
            "lumpbeam analyze needs matplotlib: pip install 'lumpbeam_ros[plots]'",
        ),
    ],
)
def test_an_optional_module_gets_its_install_line(module, command, line):
    error = ModuleNotFoundError(f'No module named {module!r}', name=module)
    assert missing_package_message(command, error) == line


@pytest.mark.parametrize(
    'module', ['numpy', 'scipy.signal', 'lumpbeam_ros.apps.cli.nothing', None]
)
def test_a_required_or_unknown_module_is_not_called_optional(module):
    error = ModuleNotFoundError('No module', name=module)
    assert missing_package_message('analyze', error) is None
