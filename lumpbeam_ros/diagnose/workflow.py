"""The discrepancy workflow: measure the gap, name the missing effect, close it.

1. Measurement error of z and pitch from the data (:mod:`~lumpbeam_ros.diagnose.noise`):
   the larger of the white noise and what a free-form fit of the free decay leaves, so a
   tracker's smooth error counts as error, not as missing physics.
2. The nominal model, identified from the record: k_tE first scaled so that the model's
   static drop at the load event matches the measured one (B.12 in ratio form), then k_tE
   and beta refit jointly by least squares on the record (``beta`` scales c_tE, B.23; only
   their product matters). Both are refit for every candidate too, because every effect
   trades off with them (added mass and a compliant mount with k_tE, friction and drag with
   beta); nothing else of the configuration is refit.
3. Signatures of the nominal model's residual (:mod:`~lumpbeam_ros.diagnose.signatures`);
   the time shift at the load event starts the latency fit.
4. Each effect fitted on the record up to ``train_fraction`` of the time after the event,
   then checked on the rest (held out), and scored (:mod:`~lumpbeam_ros.diagnose.scoring`).
5. The winner, if any, refit on the whole record; the gap before (nominal) and after
   (augmented) measured on the whole record.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from lumpbeam_ros.blas import single_threaded_blas
from lumpbeam_ros.diagnose.candidates import effect_candidates, nominal_candidate
from lumpbeam_ros.diagnose.fitting import Fit, FitProblem
from lumpbeam_ros.diagnose.gap import SETTLE_S, Gap, decay_fit, measure_gap
from lumpbeam_ros.diagnose.noise import decay_error_std, noise_std
from lumpbeam_ros.diagnose.record import Record
from lumpbeam_ros.diagnose.scoring import (
    Decision,
    Score,
    decide,
    inflation,
    information_criteria,
)
from lumpbeam_ros.diagnose.signatures import Signatures, signatures
from lumpbeam_ros.errors import LumpbeamError
from lumpbeam_ros.model.parameters import BeamParameters
from lumpbeam_ros.model.trajectory import TipTrajectory

#: Share of the time after the load event that the candidates are fitted on.
TRAIN_FRACTION = 0.6

#: Noise floor, m (and rad): noise-free synthetic data would otherwise divide by zero. At
#: 0.1 um it stays above the simulator's own error (0.03 um).
NOISE_FLOOR = 1e-7

#: Default c_tE when a configuration has none (the paper's, B.22): beta then carries the
#: damping, so any positive reference works.
DEFAULT_C_TOTAL = 0.08


@dataclass(frozen=True)
class Diagnosis:
    """What ``lumpbeam diagnose`` reports (doc/interfaces.md, 'Command line', ``diagnose`` keys).

    Attributes:
        missing_effect: An effect name of doc/interfaces.md, ``'none'`` or ``'unexplained'``.
        effect_parameters: The named effect's parameter (empty otherwise).
        gap_before: The nominal model (k_tE, beta refit) against the record.
        gap_after: The augmented model against the record (the nominal one when nothing
            is named).
        gap_configured: The configured beam as given (nothing refit) against the record.
        candidates: One score per effect, best first.
        nominal: The nominal model's score.
        decision: The verdict and its reason.
        signatures: Residual signatures of the nominal model.
        noise_z_m: Estimated z noise, m.
        noise_pitch_rad: Estimated pitch noise, rad.
        train_end_s: The candidates were fitted on the record up to here.
        nominal_beam: The refit nominal beam.
        augmented_beam: The nominal beam plus the named effect, refit on the whole record.
        record: The measurement.
        before: Nominal simulation at the record's stamps.
        after: Augmented simulation at the record's stamps.
        simulations: Model simulations the diagnosis ran.
    """

    missing_effect: str
    effect_parameters: dict[str, float]
    gap_before: Gap
    gap_after: Gap
    gap_configured: Gap
    candidates: list[Score]
    nominal: Score
    decision: Decision
    signatures: Signatures
    noise_z_m: float
    noise_pitch_rad: float
    train_end_s: float
    nominal_beam: BeamParameters
    augmented_beam: BeamParameters
    record: Record
    before: TipTrajectory
    after: TipTrajectory
    simulations: int

    def as_dict(self) -> dict[str, Any]:
        """The JSON form: the contract keys, then ``details`` for humans and plots."""
        return {
            'missing_effect': self.missing_effect,
            'effect_parameters': dict(self.effect_parameters),
            'gap_before': self.gap_before.as_dict(),
            'gap_after': self.gap_after.as_dict(),
            'candidates': [
                {'name': s.name, 'parameters': s.parameters, 'score': s.bic}
                for s in self.candidates
            ],
            'details': {
                'reason': self.decision.reason,
                'gap_configured': self.gap_configured.as_dict(),
                'score': 'BIC (lower is better) of the fit on the training part',
                'nominal': _score_details(self.nominal),
                'candidates': [_score_details(s) for s in self.candidates],
                'signatures': self.signatures.as_dict(),
                'noise_z_m': self.noise_z_m,
                'noise_pitch_rad': self.noise_pitch_rad,
                'train_end_s': self.train_end_s,
                'simulations': self.simulations,
            },
        }


def _score_details(score: Score) -> dict[str, Any]:
    return {
        'name': score.name,
        'parameters': score.parameters,
        'bic': score.bic,
        'aic': score.aic,
        'train_chi2': score.train_chi2,
        'holdout_chi2': score.holdout_chi2,
        'record_chi2': score.record_chi2,
        'physical': score.physical,
    }


def nominal_form(beam: BeamParameters) -> BeamParameters:
    """The beam in the identified form whose k_tE and beta a diagnosis refits.

    An analytic beam (B.9, c = beta k) is rewritten with the same joints: ``k_tE = k / n_s``
    (B.13) and ``beta = c / (n_s c_tE)`` (B.23).

    Args:
        beam: The configured beam.

    Returns:
        The same joints, ``stiffness_source='identified'``, with a positive c_tE and beta.
    """
    n = beam.n_segments
    c_total = beam.c_total if beam.c_total > 0.0 else DEFAULT_C_TOTAL
    damping = beam.segment_damping()
    beta = damping / (n * c_total) if damping > 0.0 else 1.0
    return replace(
        beam,
        stiffness_source='identified',
        k_total_nm_per_rad=beam.segment_stiffness() / n,
        c_total=c_total,
        beta_identified=beta,
    )


def measurement_error(record: Record) -> tuple[float, float]:
    """The error floor of z (m) and pitch (rad) that a right model's residual sits at.

    The larger of the white noise (differences) and the free-form decay fit's residual
    after the first load event (:mod:`~lumpbeam_ros.diagnose.noise`), at least
    ``NOISE_FLOOR``.

    Args:
        record: The measurement.

    Returns:
        ``(sigma_z, sigma_pitch)``.
    """
    event = record.event_time_s
    end = record.load_events[1][0] if len(record.load_events) > 1 else np.inf
    free = record.t < end  # the decay is free up to the next load change
    sigmas = []
    for y in (record.z, record.pitch):
        slow = decay_error_std(record.t[free], y[free], event + SETTLE_S, event)
        sigmas.append(max(noise_std(y), slow, NOISE_FLOOR))
    return sigmas[0], sigmas[1]


def _static_seed(model: TipTrajectory, record: Record, problem: FitProblem) -> BeamParameters:
    """Scales k_tE so the model's static drop at the event matches the data (B.12)."""
    beam = problem.nominal
    event = record.event_time_s
    before, after = record.t < event, record.t >= event + SETTLE_S
    measured = float(np.mean(record.z[after]) - np.mean(record.z[before]))
    simulated = float(np.mean(model.z[after]) - np.mean(model.z[before]))
    if abs(measured) < 10.0 * problem.sigma_z or measured * simulated <= 0.0:
        return beam  # no usable static change: keep the configured stiffness
    factor = float(np.clip(simulated / measured, 0.3, 3.0))
    return replace(beam, k_total_nm_per_rad=beam.k_total_nm_per_rad * factor)


@dataclass(frozen=True)
class _Evaluated:
    fit: Fit
    trajectory: TipTrajectory
    residuals: np.ndarray  # z then pitch, whole record


def _evaluate(problem: FitProblem, fit: Fit) -> _Evaluated:
    trajectory = problem.simulate(fit.beam)
    return _Evaluated(fit, trajectory, problem.residuals(trajectory))


def _chi2(residuals: np.ndarray, mask: np.ndarray) -> float:
    both = np.concatenate([mask, mask])
    return float(np.mean(residuals[both] ** 2))


def diagnose(
    record: Record, beam: BeamParameters, train_fraction: float = TRAIN_FRACTION
) -> Diagnosis:
    """Runs the whole workflow on one record.

    Args:
        record: The measurement with its load events.
        beam: The nominal beam (its k_tE and beta are refit; the rest is taken as is).
        train_fraction: Share of the time after the first load event fitted; the rest is
            held out.

    Returns:
        The diagnosis.

    Raises:
        LumpbeamError: ``train_fraction`` outside (0.2, 0.95), or a record whose decay
            cannot be measured.
    """
    if not 0.2 < train_fraction < 0.95:
        raise LumpbeamError(f'train fraction must lie in (0.2, 0.95), got {train_fraction}')
    with single_threaded_blas():
        return _diagnose(record, beam, train_fraction)


def _diagnose(record: Record, beam: BeamParameters, train_fraction: float) -> Diagnosis:
    sigma_z, sigma_pitch = measurement_error(record)
    problem = FitProblem(record, nominal_form(beam), sigma_z, sigma_pitch)
    configured = problem.simulate(problem.nominal)
    problem.nominal = _static_seed(configured, record, problem)
    event = record.event_time_s
    train_end = event + train_fraction * (record.t[-1] - event)
    train = record.t <= train_end
    try:
        measured_fit = decay_fit(record.t, record.z, event)
    except LumpbeamError as exc:
        raise LumpbeamError(
            f'cannot measure the free decay after the load change at {event:.3f} s: {exc}'
        ) from None
    measured_mode = measured_fit.mode(0)

    nominal_model = nominal_candidate()
    nominal = _evaluate(problem, problem.fit(nominal_model, np.zeros(2), train_end))
    sig = signatures(record, nominal.trajectory, measured_fit.offset)

    evaluated = [nominal]
    for candidate in effect_candidates(problem.nominal):
        strength = None
        if candidate.name == 'sensor_latency' and sig.time_shift_s > candidate.start:
            strength = sig.time_shift_s  # the delay seen at the load event
        x0 = candidate.start_x(nominal.fit.x, strength)
        evaluated.append(_evaluate(problem, problem.fit(candidate, x0, train_end)))

    best_train = min(evaluated, key=lambda e: e.fit.chi2)
    phi = inflation(best_train.residuals[np.concatenate([train, train])])
    n_train = int(2 * np.count_nonzero(train))
    scores = [_score(problem, e, train, n_train, phi) for e in evaluated]
    nominal_score, candidate_scores = scores[0], scores[1:]
    decision = decide(nominal_score, candidate_scores)

    # The final models use the whole record: more data, and the gaps are over all of it.
    final_nominal = _evaluate(problem, problem.fit(nominal_model, nominal.fit.x))
    augmented = final_nominal
    effect_parameters: dict[str, float] = {}
    if decision.missing_effect not in ('none', 'unexplained'):
        winner = next(e.fit for e in evaluated if e.fit.name == decision.missing_effect)
        augmented = _evaluate(problem, problem.fit(winner.candidate, winner.x))
        effect_parameters = {
            str(winner.candidate.parameter): winner.candidate.value(augmented.fit.x)
        }

    return Diagnosis(
        missing_effect=decision.missing_effect,
        effect_parameters=effect_parameters,
        gap_before=measure_gap(record, final_nominal.trajectory, measured_mode),
        gap_after=measure_gap(record, augmented.trajectory, measured_mode),
        gap_configured=measure_gap(record, configured, measured_mode),
        candidates=sorted(candidate_scores, key=lambda s: s.bic),
        nominal=nominal_score,
        decision=decision,
        signatures=sig,
        noise_z_m=sigma_z,
        noise_pitch_rad=sigma_pitch,
        train_end_s=float(train_end),
        nominal_beam=final_nominal.fit.beam,
        augmented_beam=augmented.fit.beam,
        record=record,
        before=final_nominal.trajectory,
        after=augmented.trajectory,
        simulations=problem.simulations,
    )


def _score(
    problem: FitProblem, evaluated: _Evaluated, train: np.ndarray, n_train: int, phi: float
) -> Score:
    fit = evaluated.fit
    bic, aic = information_criteria(fit.chi2, n_train, fit.candidate.n_parameters, phi)
    return Score(
        name=fit.name,
        parameters=fit.candidate.values(problem.nominal, fit.x),
        bic=bic,
        aic=aic,
        train_chi2=fit.reduced_chi2,
        holdout_chi2=_chi2(evaluated.residuals, ~train),
        record_chi2=_chi2(evaluated.residuals, np.ones_like(train)),
        physical=fit.physical,
    )
