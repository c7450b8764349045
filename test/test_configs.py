"""Every file shipped under ``config/`` is checked against what the code declares.

The node parameter files hold their schema's defaults (``test/base/test_schema.py``); the beam
file holds every key the beam, its effects and its drop test declare, each at its declared
default; the arm files load into an arm; the viewer layouts are checked against the demo's
bag (``test/core/viz/test_layouts.py``). A file with no check here fails, so a new one comes
with its check.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from lumpbeam_ros.base.paramfile import read_parameter_file
from lumpbeam_ros.base.schema import settings_specs
from lumpbeam_ros.core.model.arm.config import load_arm_config
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig, Effects
from lumpbeam_ros.nodes.params.reference import SCHEMAS

CONFIG = Path(__file__).resolve().parents[1] / 'config'

NODE_FILES = {schema.config_file for schema in SCHEMAS if schema.config_file}
BEAM_FILES = {'paper_beam.yaml'}
ARM_FILES = {p.name for p in CONFIG.glob('arm_*.yaml')}
#: Checked panel by panel against the demo's recording (test/core/viz/test_layouts.py).
LAYOUT_FILES = {'foxglove_layout.json', 'lumpbeam.rviz'}


def _plain(value):
    return tuple(value) if isinstance(value, list) else value


def test_every_shipped_file_has_a_check():
    shipped = {p.name for p in CONFIG.iterdir()}
    assert shipped == NODE_FILES | BEAM_FILES | ARM_FILES | LAYOUT_FILES


@pytest.mark.parametrize('name', sorted(BEAM_FILES))
def test_the_beam_file_holds_every_declared_key_at_its_default(name):
    values = read_parameter_file(CONFIG / name)
    specs = {
        spec.name: spec
        for cls in (BeamParameters, Effects, DropTestConfig)
        for spec in settings_specs(cls)
    }
    assert sorted(set(specs) - set(values)) == [], 'declared, not in the file'
    assert sorted(set(values) - set(specs)) == [], 'in the file, not declared'
    assert {k: _plain(v) for k, v in values.items()} == {k: s.default for k, s in specs.items()}


@pytest.mark.parametrize('name', sorted(ARM_FILES))
def test_each_arm_file_builds_an_arm(name):
    config = load_arm_config(CONFIG / name)
    model = ArmModel.from_config(config)
    assert config.n_joints == len(config.links) >= 1 and model.chain.n >= config.n_joints
