import math

import numpy as np
import pytest

from lumpbeam_ros.apps.plots.analysis import FILES, _envelope, write_analysis_plots
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.identification import Identification, Status
from lumpbeam_ros.core.ident.identify import identify
from lumpbeam_ros.core.ident.samples import clean_loads, clean_window
from lumpbeam_ros.core.model.parameters import BeamParameters


def _decay_window():
    t = np.arange(0.0, 8.0, 1 / 180)
    tau = np.maximum(t - 1.0, 0.0)
    z = -0.069 + 0.04 * (1 - np.exp(-0.05 * tau) * np.cos(2 * math.pi * 3.06 * tau))
    z += np.random.default_rng(0).normal(0, 20e-6, t.size)
    loads = clean_loads([0.0, 1.0], [4.5, 0.0])
    return clean_window(t, z, -z / 2.3, loads)


def test_figures_are_written_and_the_envelope_matches_the_fit(tmp_path):
    window = _decay_window()
    result = identify(window, BeamParameters())
    assert result.ok
    paths = write_analysis_plots(window, result, tmp_path / 'figs')
    assert [p.name for p in paths] == list(FILES)
    for path in paths:
        assert path.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n' and path.stat().st_size > 5000
    after = window.t[window.t > 1.0]
    env = _envelope(result, after)
    # Decay at sigma = 0.05/s with 4 cm at the release.
    assert env[0] == pytest.approx(0.04, rel=0.01)
    assert env[-1] / env[0] == pytest.approx(math.exp(-0.05 * (after[-1] - after[0])), rel=1e-2)


def test_an_error_result_still_plots(tmp_path):
    window = clean_window(np.arange(100) / 180, np.zeros(100))
    paths = write_analysis_plots(window, Identification(Status.ERROR, 'none'), tmp_path)
    assert all(p.exists() for p in paths)


def test_unwritable_folder_is_a_clear_error(tmp_path):
    blocker = tmp_path / 'file'
    blocker.write_text('x')
    with pytest.raises(LumpbeamError, match='cannot create plots folder'):
        write_analysis_plots(_decay_window(), Identification(Status.ERROR, 'x'), blocker / 'd')
