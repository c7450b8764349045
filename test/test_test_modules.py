"""Every ROS-free module has its test module (``test/`` mirrors the package), or is listed.

The list only shrinks: a new core module comes with its tests (take a module off the list
once it has them). ``python tools/test_modules.py`` prints the count and the list.
"""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: Core modules still tested only through the modules and commands that use them (none left).
WITHOUT_TEST_MODULE: set[str] = set()


def _tool():
    spec = importlib.util.spec_from_file_location(
        'test_modules_tool', ROOT / 'tools' / 'test_modules.py'
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_core_module_has_a_test_module_or_is_listed():
    tool = _tool()
    missing = {m.as_posix() for m in tool.missing_tests(ROOT)}
    assert missing <= WITHOUT_TEST_MODULE, (
        f'core modules without tests: {sorted(missing - WITHOUT_TEST_MODULE)}'
    )


def test_every_ros_free_lab_module_has_a_test_module():
    tool = _tool()
    assert tool.missing_tests(ROOT, tool.LAB) == []


def test_the_tool_finds_the_mirrored_path():
    tool = _tool()
    chain = Path('core/model/chain.py')
    assert tool.mirror_test_path(chain) == Path('test/core/model/test_chain.py')
    assert tool.mirror_test_path(Path('base/errors.py')) == Path('test/base/test_errors.py')
    modules = {m.as_posix() for m in tool.core_modules(ROOT)}
    assert 'core/model/chain.py' in modules and 'nodes/recorder.py' not in modules
    assert 'nodes/realtime.py' in modules and 'apps/cli/main.py' not in modules
    assert not any(m.endswith('__init__.py') for m in modules)


def test_the_lab_is_mirrored_under_test_lab():
    tool = _tool()
    assert tool.mirror_test_path(Path('camera/validation.py'), tool.LAB) == Path(
        'test/lab/camera/test_validation.py'
    )
    modules = {m.as_posix() for m in tool.core_modules(ROOT, tool.LAB)}
    assert {'mujoco_arm.py', 'camera/raycast_camera.py'} <= modules
    assert not any(m.startswith('bench/') for m in modules)
    core = {m.as_posix() for m in tool.core_modules(ROOT)}
    assert 'bench/runner.py' not in core and 'core/vision/accuracy.py' not in core
