import numpy as np
import pytest

from lumpbeam_ros.core.diagnose.scoring import Score, decide, inflation, information_criteria


def _score(name, bic, holdout=1.0, record=1.0, physical=True):
    return Score(name, {}, bic, bic, 1.0, holdout, record, physical)


NOMINAL_FITS = _score('nominal', 1000.0)
NOMINAL_OFF = _score('nominal', 90000.0, holdout=300.0, record=100.0)


@pytest.mark.parametrize(
    ('nominal', 'candidates', 'expected'),
    [
        # Clearly better than the nominal model and the runner-up, down to the noise.
        (
            NOMINAL_OFF,
            [_score('added_mass', 1000.0), _score('base_compliance', 5000.0, 9)],
            'added_mass',
        ),
        # Nothing beats a nominal model that fits: none.
        (NOMINAL_FITS, [_score('added_mass', 995.0), _score('base_compliance', 1008.0)], 'none'),
        # Two candidates tie: no confident name.
        (
            NOMINAL_OFF,
            [_score('added_mass', 1000.0), _score('base_compliance', 1004.0)],
            'unexplained',
        ),
        # The best one still leaves a gap: unexplained.
        (
            NOMINAL_OFF,
            [
                _score('quadratic_drag', 5000.0, 40.0, 20.0),
                _score('added_mass', 9000.0, 60.0, 30.0),
            ],
            'unexplained',
        ),
        # The best one needs an absurd parameter: unexplained.
        (
            NOMINAL_OFF,
            [_score('added_mass', 1000.0, physical=False), _score('sensor_latency', 9000.0, 9)],
            'unexplained',
        ),
        # Better in BIC but worse on the held-out part than the runner-up: no name.
        (
            NOMINAL_OFF,
            [_score('added_mass', 1000.0, 1.3), _score('sensor_latency', 1100.0, 1.2)],
            'unexplained',
        ),
        # Significant over a nominal model that is within the noise: a weak effect, named.
        (
            NOMINAL_FITS,
            [_score('sensor_latency', 900.0, 0.9), _score('added_mass', 1000.0)],
            'sensor_latency',
        ),
    ],
)
def test_decision_rules(nominal, candidates, expected):
    decision = decide(nominal, candidates)
    assert decision.missing_effect == expected, decision.reason
    assert decision.best == min(candidates, key=lambda s: s.bic).name


def test_inflation_is_one_for_white_noise_and_large_for_a_slow_pattern():
    rng = np.random.default_rng(0)
    white = rng.standard_normal(4000)
    assert inflation(white) == pytest.approx(1.0, abs=0.1)
    t = np.arange(2000) / 180.0
    pattern = np.tile(np.sin(2 * np.pi * 3 * t), 2) + 0.1 * rng.standard_normal(4000)
    assert inflation(pattern) > 20.0


def test_information_criteria_penalise_parameters_and_deflate_correlated_evidence():
    bic2, aic2 = information_criteria(1000.0, 4000, 2, 1.0)
    bic3, aic3 = information_criteria(1000.0, 4000, 3, 1.0)
    assert bic3 - bic2 == pytest.approx(np.log(4000))
    assert aic3 - aic2 == pytest.approx(2.0)
    assert information_criteria(1000.0, 4000, 2, 10.0)[0] < bic2
