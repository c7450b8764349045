import numpy as np

from lumpbeam_lab.ident import modes_accuracy
from lumpbeam_lab.ident.modes_accuracy import Record, minimum_jerk, score
from lumpbeam_ros.core.ident.identification import Estimate, Identification, IdentifiedMode, Status


def test_score_counts_found_modes_errors_and_coverage():
    t = np.arange(10) / 180.0

    def identify(x, z):
        # A fixed answer: mode 1 off by 2 sigma, mode 2 off by 4 sigma, and a spurious mode.
        return Identification(
            Status.OK,
            '',
            modes=(
                IdentifiedMode(Estimate(1.02, 0.01), Estimate(0.01, 0.001), 1e-3),
                IdentifiedMode(Estimate(5.0, 0.1), Estimate(0.024, 0.001), 1e-4),
                IdentifiedMode(Estimate(9.0, 0.1), Estimate(0.02, 0.001), 1e-5),
            ),
        )

    record = Record('fixed', t, t, t, ((1.0, 0.01), (5.0, 0.02), (20.0, 0.1)), identify)
    lines = score(record, 3)
    assert lines[0].startswith('fixed: 3 trials (seeds 0..2), 0 failed, 3 reported modes')
    assert 'found in 3/3 trials' in lines[1]
    assert 'rms 2.0000 %, bias +2.0000 %' in lines[2] and 'within 3 sigma: 3/3' in lines[2]
    assert 'damping:   rms 20.0000 %' in lines[6] and 'within 3 sigma: 0/3 = 0.0 %' in lines[6]
    assert 'found in 0/3 trials' in lines[7] and 'n/a' in lines[8]


def test_the_scenarios_are_named_and_the_move_ends_at_rest():
    move = minimum_jerk([0.0], [0.5], 0.4)
    assert move.angles_rad[-1, 0] == 0.5 and move.time_s[-1] == 0.4
    assert len(modes_accuracy.scenarios()) == 4


def test_a_drop_record_is_identified_as_analyze_does():
    record = modes_accuracy.drop_record('drop', 0.5, 4.5, 2)
    lines = score(record, 1)
    assert 'found in 1/1 trials' in lines[1] and 'found in 1/1 trials' in lines[4]
