"""The discrepancy workflow: measure the gap, name the missing effect, close it.

1. Measurement error of z and pitch from the data (:mod:`~lumpbeam_ros.core.diagnose.noise`):
   the larger of the white noise and what a free-form fit of the free decay leaves, so a
   tracker's smooth error counts as error, not as missing physics.
2. The nominal model, identified from the record: k_tE first scaled so that the model's
   static drop at the load event matches the measured one (B.12 in ratio form), then k_tE
   and beta refit jointly by least squares on the record (``beta`` scales c_tE, B.23; only
   their product matters). Both are refit for every candidate too, because every effect
   trades off with them (added mass and a compliant mount with k_tE, friction and drag with
   beta); nothing else of the configuration is refit.
3. Signatures of the nominal model's residual (:mod:`~lumpbeam_ros.core.diagnose.signatures`);
   the time shift at the load event starts the latency fit.
4. Forward selection (:mod:`~lumpbeam_ros.core.diagnose.selection`): every effect fitted on the
   record up to ``train_fraction`` of the time after the event, checked on the rest (held
   out) and scored (:mod:`~lumpbeam_ros.core.diagnose.scoring`); the best joins the model when
   the data insist on it, and a second effect is searched on top of it the same way (a
   pair only on a decay of at least ``PAIR_MIN_DECAY_S``). Dry friction's fits start where
   the decay envelopes put them (:func:`dry_friction_start`).
5. The selected model, if any, refit on the whole record; the gap before (nominal) and
   after (augmented) measured on the whole record.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from lumpbeam_ros.base.blas import single_threaded_blas
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.diagnose.candidates import Candidate, effect_candidates, nominal_candidate
from lumpbeam_ros.core.diagnose.fitting import FitProblem
from lumpbeam_ros.core.diagnose.gap import SETTLE_S, Gap, decay_fit, measure_gap
from lumpbeam_ros.core.diagnose.measurement import Record
from lumpbeam_ros.core.diagnose.noise import decay_error_std, noise_std
from lumpbeam_ros.core.diagnose.scoring import (
    NONE,
    UNEXPLAINED,
    Decision,
    Score,
    explains,
    unexplained_reason,
)
from lumpbeam_ros.core.diagnose.selection import (
    MAX_EFFECTS,
    PAIR_MIN_DECAY_S,
    Evaluated,
    Model,
    Selection,
    Selector,
    select,
)
from lumpbeam_ros.core.diagnose.signatures import (
    Signatures,
    decay_peaks,
    envelope_rates,
    signatures,
)
from lumpbeam_ros.core.model.parameters import BeamParameters
from lumpbeam_ros.core.model.simulate import SimulationDivergedError
from lumpbeam_ros.core.model.trajectory import TipTrajectory

#: Share of the time after the load event that the candidates are fitted on.
TRAIN_FRACTION = 0.6

#: Noise floor, m (and rad): noise-free synthetic data would otherwise divide by zero. At
#: 0.1 um it stays above the simulator's own error (0.03 um).
NOISE_FLOOR = 1e-7

#: Default c_tE when a configuration has none (the paper's, B.22): beta then carries the
#: damping, so any positive reference works.
DEFAULT_C_TOTAL = 0.08


@dataclass(frozen=True)
class NamedEffect:
    """One effect the diagnosis names.

    Attributes:
        name: The effect's name (doc/interfaces.md, 'Missing effects').
        parameters: ``{parameter: value}``, SI, fitted on the whole record with the others.
        gap_reduction: Share of the tip-z RMS gap (over the whole record) that adding it
            removed, from the model before it to the model with it.
    """

    name: str
    parameters: dict[str, float]
    gap_reduction: float

    def as_dict(self) -> dict[str, Any]:
        """``{name, parameters, gap_reduction}``."""
        return {
            'name': self.name,
            'parameters': dict(self.parameters),
            'gap_reduction': self.gap_reduction,
        }


@dataclass(frozen=True)
class Diagnosis:
    """What ``lumpbeam diagnose`` reports (doc/interfaces.md, 'Command line', ``diagnose`` keys).

    Attributes:
        missing_effect: The first named effect, ``'none'`` or ``'unexplained'``.
        effect_parameters: Every named effect's parameter (empty otherwise).
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
        missing_effects: Every named effect, in the order chosen.
        confidence: BIC posterior probability of the answer's path (product over rounds).
        rounds: The selection's rounds (JSON form).
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
    missing_effects: tuple[NamedEffect, ...] = ()
    confidence: float = 1.0
    rounds: tuple[dict[str, Any], ...] = ()

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
            'missing_effects': [e.as_dict() for e in self.missing_effects],
            'confidence': self.confidence,
            'n_samples': len(self.record),
            'n_rejected': self.record.counts.n_rejected,
            'details': {
                'reason': self.decision.reason,
                'rounds': [dict(r) for r in self.rounds],
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
    after the first load event (:mod:`~lumpbeam_ros.core.diagnose.noise`), at least
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


def _envelope(t: np.ndarray, z: np.ndarray, event_s: float) -> tuple[float, float]:
    """Viscous and dry decay terms of a record's free decay (NaN if unmeasurable)."""
    try:
        level = decay_fit(t, z, event_s).offset
    except LumpbeamError:
        return float('nan'), float('nan')
    return envelope_rates(*decay_peaks(t, z, event_s, level))


def dry_friction_start(
    problem: FitProblem, base: Model, base_x: np.ndarray, candidate: Candidate, end_s: float
) -> np.ndarray | None:
    """Where a fit of dry friction added to a fitted model should start, from the envelopes.

    A model without friction mimics a linear decay envelope with extra viscous damping, and
    a fit from there crawls along the valley where the two trade off (a dozen iterations from
    0.1 to 1 N m). The envelopes separate them
    (:func:`~lumpbeam_ros.core.diagnose.signatures.envelope_rates`): the viscous term scales with
    beta, the dry term with the torque. So beta is scaled by the measured viscous term over
    the model's, and the torque is the candidate's starting torque scaled by the measured
    dry term over the one that torque adds to the model (one probe simulation).

    Args:
        problem: The record and the nominal beam.
        base: The fitted model that friction would join.
        base_x: Its parameters.
        candidate: The dry friction candidate.
        end_s: Last fitted time, s.

    Returns:
        The start ``x`` of ``base.plus(candidate)``, or ``None`` when an envelope cannot be
        measured or does not show the dry term.
    """
    record = problem.record
    event = record.event_time_s
    keep = record.t <= end_s
    probe_x = np.r_[base_x, candidate.start / candidate.scale]
    try:
        base_run = problem.trajectory(base, base_x, end_s)
        probe = problem.trajectory(base.plus(candidate), probe_x, end_s)
    except (SimulationDivergedError, RuntimeError):
        return None
    a_data, b_data = _envelope(record.t[keep], record.z[keep], event)
    a_base, b_base = _envelope(base_run.t, base_run.z, event)
    _, b_probe = _envelope(probe.t, probe.z, event)
    per_probe = b_probe - b_base
    values = (a_data, b_data, a_base, b_base, b_probe)
    if not all(np.isfinite(values)) or min(a_data, a_base, per_probe) <= 0.0:
        return None
    x: np.ndarray = np.array(probe_x, dtype=float)
    x[1] += math.log(a_data / a_base)
    x[-1] *= max(b_data - b_base, 0.0) / per_probe
    return x


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


def diagnose(
    record: Record,
    beam: BeamParameters,
    train_fraction: float = TRAIN_FRACTION,
    exhaustive: bool = False,
) -> Diagnosis:
    """Runs the whole workflow on one record.

    Args:
        record: The measurement with its load events.
        beam: The nominal beam (its k_tE and beta are refit; the rest is taken as is).
        train_fraction: Share of the time after the first load event fitted; the rest is
            held out.
        exhaustive: Fit every combination of effects from scratch instead of screening
            (the baseline of ``lumpbeam bench``; same verdicts, many times slower).

    Returns:
        The diagnosis.

    Raises:
        LumpbeamError: ``train_fraction`` outside (0.2, 0.95), or a record whose decay
            cannot be measured.
    """
    if not 0.2 < train_fraction < 0.95:
        raise LumpbeamError(f'train fraction must lie in (0.2, 0.95), got {train_fraction}')
    with single_threaded_blas():
        return _diagnose(record, beam, train_fraction, exhaustive)


def _diagnose(
    record: Record, beam: BeamParameters, train_fraction: float, exhaustive: bool
) -> Diagnosis:
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
    nominal = problem.fit(nominal_model, np.zeros(2), train_end)
    nominal_trajectory = problem.trajectory(nominal_model, nominal.x)
    sig = signatures(record, nominal_trajectory, measured_fit.offset)

    def start_strength(candidate: Candidate) -> float | None:
        if candidate.name == 'sensor_latency' and sig.time_shift_s > candidate.start:
            return sig.time_shift_s  # the delay seen at the load event
        return None

    def informed_start(base: Evaluated, candidate: Candidate) -> np.ndarray | None:
        if candidate.name != 'coulomb_friction':
            return None
        return dry_friction_start(problem, base.model, base.fit.x, candidate, train_end)

    max_effects, limit = _effects_allowed(record)
    selector = Selector(problem, train, train_end)
    selection = select(
        selector,
        nominal,
        effect_candidates(problem.nominal),
        max_effects,
        start_strength,
        exhaustive,
        informed_start,
    )
    decision = _decision(selection, limit)

    final_nominal, before, augmented_beam, after, named = _final_models(
        problem, nominal.x, selection, decision, train
    )
    return Diagnosis(
        missing_effect=decision.missing_effect,
        effect_parameters={k: v for e in named for k, v in e.parameters.items()},
        gap_before=measure_gap(record, before, measured_mode),
        gap_after=measure_gap(record, after, measured_mode),
        gap_configured=measure_gap(record, configured, measured_mode),
        candidates=sorted(selection.singles, key=lambda s: s.bic),
        nominal=selection.nominal.score,
        decision=decision,
        signatures=sig,
        noise_z_m=sigma_z,
        noise_pitch_rad=sigma_pitch,
        train_end_s=float(train_end),
        nominal_beam=final_nominal,
        augmented_beam=augmented_beam,
        record=record,
        before=before,
        after=after,
        simulations=problem.simulations,
        missing_effects=named,
        confidence=selection.confidence,
        rounds=tuple(r.as_dict() for r in selection.rounds),
    )


def _effects_allowed(record: Record) -> tuple[int, str]:
    """The policy: how many effects the record's decay can tell apart, and why not more.

    Returns:
        The most effects to name, and the reason for a limit below ``MAX_EFFECTS`` (``''``).
    """
    decay_s = _decay_length(record)
    if decay_s >= PAIR_MIN_DECAY_S:
        return MAX_EFFECTS, ''
    return 1, (
        f'the decay ({decay_s:.1f} s) is too short for a pair of effects (at least '
        f'{PAIR_MIN_DECAY_S:g} s): one effect at most'
    )


def _final_models(
    problem: FitProblem,
    nominal_x: np.ndarray,
    selection: Selection,
    decision: Decision,
    train: np.ndarray,
) -> tuple[BeamParameters, TipTrajectory, BeamParameters, TipTrajectory, tuple[NamedEffect, ...]]:
    """The nominal and the augmented model refit on the whole record, and simulated.

    The whole record: more data than the training part, and the gaps are over all of it.

    Returns:
        The nominal beam and its simulation, the augmented beam and its simulation (the
        nominal ones when nothing is named), and the effects named.
    """
    final_nominal = problem.fit(nominal_candidate(), nominal_x)
    before = problem.trajectory(nominal_candidate(), final_nominal.x)
    if decision.missing_effect in (NONE, UNEXPLAINED):
        return final_nominal.beam, before, final_nominal.beam, before, ()
    chosen = selection.model
    final = problem.fit(chosen.model, chosen.fit.x)
    named = _named(chosen.model, final.x, selection.path, problem.sigma_z, train)
    return final_nominal.beam, before, final.beam, problem.trajectory(chosen.model, final.x), named


def _decay_length(record: Record) -> float:
    """Seconds of free decay after the first load event (up to the next one or the end)."""
    event = record.event_time_s
    end = record.load_events[1][0] if len(record.load_events) > 1 else record.t[-1]
    return float(min(end, record.t[-1]) - event)


def _decision(selection: Selection, limit: str) -> Decision:
    """The verdict of a selection: its effects, ``none`` or ``unexplained``, and why."""
    rounds = selection.rounds
    last = rounds[-1].decision
    best = rounds[0].decision.best
    model = selection.model
    names = model.model.names
    reasons = [r.decision.reason for r in rounds if r.decision.keep]
    if not last.keep:
        reasons.append(last.reason)
    if limit:
        reasons.append(limit)
    reason = '; '.join(reasons)
    if selection.unphysical:
        return Decision(UNEXPLAINED, best, reason)
    if not explains(model.score):
        return Decision(UNEXPLAINED, best, f'{unexplained_reason(model.score)}; {reason}')
    return Decision(names[0] if names else NONE, best, reason)


def _named(
    model: Model,
    x: np.ndarray,
    path: list[Evaluated],
    sigma_z: float,
    train: np.ndarray,
) -> tuple[NamedEffect, ...]:
    """The named effects with their whole-record parameters and the gap each one removed."""
    count = train.size

    def rms(evaluated: Evaluated) -> float:
        return float(np.sqrt(np.mean(evaluated.residuals[:count] ** 2)) * sigma_z)

    out = []
    for i, (name, params) in enumerate(model.effect_values(x)):
        before, after = rms(path[i]), rms(path[i + 1])
        out.append(NamedEffect(name, params, 1.0 - after / before if before > 0 else 0.0))
    return tuple(out)
