"""Diagnosis figures: every file written, the signature panels name their effects."""

import matplotlib.pyplot as plt
import numpy as np
import pytest

from apps.report.helpers import late_diagnosis
from lumpbeam_ros.apps.plots.diagnosis import FIGURES, plot_diagnosis, signature_figure
from lumpbeam_ros.base.errors import LumpbeamError


@pytest.fixture(scope='module')
def late():
    """A short ring-down whose camera is 15 ms late, diagnosed."""
    return late_diagnosis()


def test_every_figure_is_written(late, tmp_path):
    paths = plot_diagnosis(late, tmp_path / 'figures')
    assert [p.name for p in paths] == list(FIGURES)
    assert all(p.stat().st_size > 10_000 for p in paths)


def test_the_signature_panels_name_their_effects_and_mark_the_one_found(late):
    assert late.missing_effect == 'sensor_latency'
    fig = signature_figure(late)
    try:
        titles = [ax.get_title() for ax in fig.axes]
        assert titles[0].startswith('sensor_latency\n') and 'time shift' in titles[0]
        assert f'{late.signatures.time_shift_s * 1e3:+.1f} ms' in titles[0]
        assert 'cubic_stiffness' in titles[1] and 'frequency against amplitude' in titles[1]
        assert 'coulomb_friction' in titles[2] and 'envelope law' in titles[2]
        colors = [ax.title.get_color() for ax in fig.axes]
        assert colors == ['C2', 'k', 'k']  # the latency panel singled out the effect
        # The measured swing is drawn: peaks over the decay, frequencies near the beam's.
        measured = fig.axes[1].lines[0].get_ydata()
        assert measured.size >= 8 and np.all((measured > 2.0) & (measured < 5.0))
    finally:
        plt.close(fig)


def test_an_unwritable_folder_is_one_error(late, tmp_path):
    blocker = tmp_path / 'file'
    blocker.write_text('')
    with pytest.raises(LumpbeamError, match='cannot write figures'):
        plot_diagnosis(late, blocker / 'figures')
