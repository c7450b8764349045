"""The joint refinement of offset and transform against the simulated truth.

It finds the truth from a wrong start, its standard deviations cover the error, and it refuses
data that cannot decide.
"""

import numpy as np
import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.compare.refine import MIN_PAIRS, refine_alignment
from lumpbeam_ros.core.compare.streams import GapInterpolator
from lumpbeam_ros.core.compare.transforms import RigidTransform

from .helpers import make_pair, with_reference


def _margin(pair) -> float:
    return 2.0 * pair.reference.period_s


def _perturbed(truth: RigidTransform, angle_deg: float, shift_m: float) -> RigidTransform:
    turn = RigidTransform.from_euler_deg((angle_deg, -angle_deg, angle_deg), (0.0, 0.0, 0.0))
    return RigidTransform(turn.rotation @ truth.rotation, truth.translation + shift_m)


@pytest.mark.parametrize(
    ('offset_error_s', 'angle_deg', 'shift_m'),
    [(0.0, 0.0, 0.0), (2e-3, 0.5, 0.01), (-3e-3, -1.0, -0.02)],
)
def test_converges_to_the_simulated_truth_from_a_wrong_start(
    pair, offset_error_s, angle_deg, shift_m
):
    truth = pair.tracker.transform
    start = _perturbed(truth, angle_deg, shift_m)
    offset = pair.tracker.clock_offset_s + offset_error_s
    found = refine_alignment(
        pair.camera, GapInterpolator(pair.reference), offset, start, _margin(pair)
    )
    assert found.iterations < 30
    # Within 5 of its own standard deviations of the truth the simulation put in.
    assert abs(found.offset_s - pair.tracker.clock_offset_s) < 5 * found.offset_std_s
    assert found.transform.angle_to(truth) < 5 * np.linalg.norm(found.rotation_std_rad)
    error = found.transform.translation - truth.translation
    assert np.all(np.abs(error) < 5 * found.translation_std_m + 1e-9)
    # The residuals are the sensors' noise (camera 20 um and tracker 15 um per axis).
    assert 10e-6 < found.pair_rms_m < 40e-6
    assert found.plane_rms_m < 40e-6
    assert found.pairs.sum() >= MIN_PAIRS
    assert found.offset_std_s >= found.offset_std_white_s > 0.0


def test_the_answer_does_not_depend_on_the_start(pair):
    truth, offset = pair.tracker.transform, pair.tracker.clock_offset_s
    reference = GapInterpolator(pair.reference)
    a = refine_alignment(pair.camera, reference, offset, truth, _margin(pair))
    b = refine_alignment(
        pair.camera, reference, offset + 2e-3, _perturbed(truth, 0.8, 0.01), _margin(pair)
    )
    # The start only moves the edges of the plane block by a sample or two: far inside the
    # answer's own uncertainty.
    assert abs(b.offset_s - a.offset_s) < 0.01 * a.offset_std_s
    assert b.transform.angle_to(a.transform) < 0.2 * np.linalg.norm(a.rotation_std_rad)
    assert np.all(
        np.abs(b.transform.translation - a.transform.translation) < 0.2 * a.translation_std_m
    )


def test_a_reference_that_does_not_move_is_refused(pair):
    still = np.tile(pair.reference.points.mean(axis=0), (len(pair.reference), 1))
    reference = with_reference(pair, np.ones(len(pair.reference), bool), still)
    with pytest.raises(LumpbeamError, match='not determined by the data'):
        refine_alignment(
            pair.camera,
            GapInterpolator(reference),
            pair.tracker.clock_offset_s,
            pair.tracker.transform,
            _margin(pair),
        )


def test_too_little_overlap_is_refused(pair):
    # Keep only the reference's first 25 ms (25 samples): 4 camera samples meet it.
    keep = pair.reference.t < pair.reference.t[0] + 0.025
    reference = with_reference(pair, keep)
    with pytest.raises(LumpbeamError, match=f'need {MIN_PAIRS}'):
        refine_alignment(
            pair.camera,
            GapInterpolator(reference),
            pair.tracker.clock_offset_s,
            pair.tracker.transform,
            _margin(pair),
        )


def test_a_noisier_camera_widens_the_offset_uncertainty():
    quiet = make_pair(duration=4.0, camera_noise=10e-6, seed=3)
    noisy = make_pair(duration=4.0, camera_noise=80e-6, seed=3)
    fits = [
        refine_alignment(
            p.camera,
            GapInterpolator(p.reference),
            p.tracker.clock_offset_s,
            p.tracker.transform,
            _margin(p),
        )
        for p in (quiet, noisy)
    ]
    assert fits[1].offset_std_white_s > 3 * fits[0].offset_std_white_s
