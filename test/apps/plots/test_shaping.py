"""The live loop's figure: written, and its failure to write one line."""

import numpy as np
import pytest

from lumpbeam_ros.apps.plots.shaping import plot_shaping_outcome
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.arm.moves import Move
from lumpbeam_ros.core.shaping.loop import MoveResidual, ShapingOutcome


def _residual(amplitude):
    t = np.arange(0.0, 3.0, 1 / 180)
    distance = amplitude * np.abs(np.exp(-0.3 * t) * np.cos(2 * np.pi * 4 * t))
    rms = float(np.sqrt(np.mean(distance**2)))
    return MoveResidual(Move(0.0, 0.3, np.zeros(1)), rms, (1.0, 0.0), t, distance)


def test_the_figure_is_written_with_both_residuals(tmp_path):
    outcome = ShapingOutcome(_residual(0.04), _residual(0.001))
    assert outcome.reduction == pytest.approx(0.975)
    path = plot_shaping_outcome(outcome, tmp_path / 'figs' / 'loop.png')
    assert path.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n' and path.stat().st_size > 5000


def test_an_unwritable_path_is_one_line(tmp_path):
    (tmp_path / 'file').write_text('')
    outcome = ShapingOutcome(_residual(0.04), _residual(0.001))
    with pytest.raises(LumpbeamError, match='cannot write the plot'):
        plot_shaping_outcome(outcome, tmp_path / 'file' / 'loop.png')
