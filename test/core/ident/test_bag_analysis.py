"""The identification of a recorded bag against the simulated beam's own first mode."""

import pytest

from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.core.bagio import BagWriter
from lumpbeam_ros.core.ident.bag_analysis import (
    CONTRACT_KEYS,
    analyze_bag,
    read_window,
    result_json,
)
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.model.adopt import first_mode
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag

BEAM, DROP = load_beam_config(None)


@pytest.fixture(scope='module')
def drop_bag(tmp_path_factory):
    bag = tmp_path_factory.mktemp('ident') / 'bag'
    write_drop_test_bag(bag, BEAM, DROP, SynthOptions(duration_s=8.0, markers_rate_hz=0.0))
    return bag


def test_a_drop_test_gives_the_beams_first_mode(drop_bag):
    analysis = analyze_bag(drop_bag, BEAM, IdentifierConfig(), show_progress=False)
    assert analysis.result.ok
    figures = result_json(analysis.result)
    # The modal analysis of the same chain after the release (linearized about its rest).
    f_n, f_d, zeta = first_mode(BEAM, 0.0)  # the whole load leaves
    assert figures['natural_frequency_hz'] == pytest.approx(f_n, rel=2e-3)
    assert figures['damped_frequency_hz'] == pytest.approx(f_d, rel=2e-3)
    assert figures['damping_ratio'] == pytest.approx(zeta, rel=0.25)
    for key in CONTRACT_KEYS:
        assert key in figures and f'{key}_std' in figures
    assert len(analysis.window) == 8 * 180 + 1 and analysis.notes == ()


def test_read_window_has_every_pose(drop_bag):
    window = read_window(drop_bag, show_progress=False)
    assert len(window) == 8 * 180 + 1
    assert window.end_s - window.start_s == pytest.approx(8.0)


def test_a_bag_without_poses_is_refused(tmp_path):
    bag = tmp_path / 'loads_only'
    with BagWriter(bag) as writer:
        writer.write_float('/tip_load', 0.0, 4.5)
    with pytest.raises(BagError, match='/tip_pose'):
        analyze_bag(bag, BEAM, IdentifierConfig(), show_progress=False)


def test_too_short_a_record_is_named_with_the_bag(tmp_path):
    bag = tmp_path / 'short'
    with BagWriter(bag) as writer:
        for i in range(5):
            writer.write_pose('/tip_pose', 0.01 * i, 2.3, -0.02, 0.01)
    with pytest.raises(LumpbeamError, match=str(bag)):
        analyze_bag(bag, BEAM, IdentifierConfig(), show_progress=False)
