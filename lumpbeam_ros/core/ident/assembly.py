"""An identification put together: the physics derived from a fit, graded, in the result's form.

:mod:`~lumpbeam_ros.core.ident.identify` fits a window and runs the cross-checks; this module
turns what it found into the :class:`~lumpbeam_ros.core.ident.identification.Identification`
of doc/interfaces.md: k_tE from the static rise (B.12), c_tE from the damping (B.22), the
frequency's stiffness as a cross-check, the grade (OK or WARN, and why) and the groups of
the result.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from lumpbeam_ros.core.bagio.tipseries import MAX_DROPPED_FRACTION, SampleCounts
from lumpbeam_ros.core.ident import stiffness
from lumpbeam_ros.core.ident.identification import (
    UNKNOWN,
    AnalysedWindow,
    CrossCheckFigures,
    Estimate,
    Estimates,
    FitQuality,
    Identification,
    IdentifiedMode,
    ReleaseFigures,
    Status,
)
from lumpbeam_ros.core.ident.logdec import LogDecrementResult
from lumpbeam_ros.core.ident.mode_estimate import ModeEstimate
from lumpbeam_ros.core.ident.modes import structural_modes
from lumpbeam_ros.core.ident.release import Release
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.ident.sinusoid import DampedSinusoidParameters
from lumpbeam_ros.core.model import rules
from lumpbeam_ros.core.model.parameters import BeamParameters

NAN = float('nan')
#: The estimator's name in the result (``method``), before its modes and nonlinearity.
METHOD = 'nls_damped_sinusoid'


@dataclass(frozen=True)
class CrossChecks:
    """The independent estimates the headline figures are compared with.

    Attributes:
        pencil: The matrix pencil's (f_n, zeta) of the first mode.
        logdec: The paper's log decrement (B.20, B.21), ``None`` when it failed.
        pitch_stiffness: k_tE and its std from the fall of the static pitch.
    """

    pencil: tuple[float, float]
    logdec: LogDecrementResult | None
    pitch_stiffness: tuple[float, float]


@dataclass(frozen=True)
class FitState:
    """What the identification of a slightly later window can start from.

    Attributes:
        release_time_s: The release the fit started at (NaN: none in the window).
        params: The fitted decay.
        checks: The cross-checks of the last full identification.
        checked_at_s: Window end of the last full identification.
    """

    release_time_s: float
    params: DampedSinusoidParameters
    checks: CrossChecks
    checked_at_s: float


def released_load(release: Release, config: IdentifierConfig) -> float:
    """The released mass: from ``/tip_load``, else the configured one."""
    return release.load_kg if math.isfinite(release.load_kg) else config.assumed_load_kg


def lowest_mode(params: DampedSinusoidParameters) -> int:
    """The index of the fitted mode of lowest frequency: the first mode of the report."""
    return min(structural_modes(params), key=lambda m: params.mode(m).natural_frequency_hz)


def identified_modes(params: DampedSinusoidParameters) -> tuple[IdentifiedMode, ...]:
    """Every fitted mode (not a harmonic) with its standard deviations, by frequency."""
    modes = sorted(
        (params.mode(m) for m in structural_modes(params)), key=lambda m: m.natural_frequency_hz
    )
    return tuple(
        IdentifiedMode(
            Estimate(m.natural_frequency_hz, m.natural_frequency_hz_std),
            Estimate(m.damping_ratio, m.damping_ratio_std),
            m.amplitude,
        )
        for m in modes
    )


def _damping_total(params: DampedSinusoidParameters, mode: ModeEstimate) -> tuple[float, float]:
    """c_tE = 2 zeta omega_d (B.22) and its std from the (sigma, omega_d) covariance."""
    part = params.mode_slice(lowest_mode(params))
    s, w = params.x[part][2:]
    wn = math.hypot(s, w)
    value = rules.total_damping_from_ratio(mode.damping_ratio, mode.damped_omega)
    grad = np.array([2.0 * w**3 / wn**3, 2.0 * s**3 / wn**3])
    cov = params.covariance.matrix[part, part][2:, 2:]
    return value, float(math.sqrt(max(grad @ cov @ grad, 0.0)))


@dataclass(frozen=True)
class Figures:
    """What the physics derives from a fitted decay and the release (B.12, B.22).

    Attributes:
        cycles: Cycles of the first mode fitted.
        damping_total: c_tE and its std (B.22).
        load_kg: The released mass.
        level_after: Static tip level after the release (the fit's offset) and its std.
        deflection: Rise of the static level at the release and its std.
        static: k_tE (B.12) and the vertical stiffness from that rise.
        stiffness_from_frequency: ``m_eff (2 pi f_n)^2`` and its std (a cross-check).
    """

    cycles: float
    damping_total: tuple[float, float]
    load_kg: float
    level_after: tuple[float, float]
    deflection: tuple[float, float]
    static: stiffness.StaticStiffness
    stiffness_from_frequency: tuple[float, float]


def assemble(
    beam: BeamParameters,
    config: IdentifierConfig,
    release: Release,
    t: np.ndarray,
    state: FitState,
    mode: ModeEstimate,
    span: AnalysedWindow,
    tally: SampleCounts,
) -> Identification:
    """The identification of a fitted window: its figures, graded, in the result's form."""
    figures = _derive(beam, config, release, t, state.params, mode)
    warnings = _grade(config, release, mode, figures, state.checks, tally)
    if warnings:
        status, message = Status.WARN, '; '.join(warnings)
    else:
        status = Status.OK
        message = (
            f'f_n {mode.natural_frequency_hz:.4f} Hz, zeta {mode.damping_ratio:.4g}, '
            f'k_tE {figures.static.total_nm_per_rad:.1f} N m/rad over {figures.cycles:.1f} '
            'cycles'
        )
    return _report(status, message, release, state, mode, figures, span, tally)


def _derive(
    beam: BeamParameters,
    config: IdentifierConfig,
    release: Release,
    t: np.ndarray,
    params: DampedSinusoidParameters,
    mode: ModeEstimate,
) -> Figures:
    """The physics: damping (B.22) and stiffness (B.12, and from the frequency)."""
    load = released_load(release, config)
    tip_mass = beam.tip_mass_kg + (
        release.load_after_kg if math.isfinite(release.load_after_kg) else 0.0
    )
    k_freq = (
        stiffness.from_frequency(
            mode.natural_frequency_hz,
            mode.natural_frequency_hz_std,
            tip_mass,
            beam.mass_kg,
            config.beam_mass_fraction,
        )
        if release.load_kg != 0.0
        else (NAN, NAN)  # an arm's ring-down: the clamped beam's effective mass does not apply
    )
    level_after, level_after_std = params.offset, params.offset_std
    deflection = level_after - release.level_before_m
    deflection_std = math.hypot(level_after_std, release.level_before_std_m)
    after = release.load_after_kg if math.isfinite(release.load_after_kg) else 0.0
    static = stiffness.from_static_change(
        deflection, deflection_std, load, beam.length_m, beam.gravity_mps2,
        stiffness.formula_share(beam, after, load),
    )  # fmt: skip
    return Figures(
        cycles=float((t[-1] - t[0]) * mode.damped_frequency_hz),
        damping_total=_damping_total(params, mode),
        load_kg=load,
        level_after=(level_after, level_after_std),
        deflection=(deflection, deflection_std),
        static=static,
        stiffness_from_frequency=k_freq,
    )


def _grade(
    config: IdentifierConfig,
    release: Release,
    mode: ModeEstimate,
    figures: Figures,
    checks: CrossChecks,
    tally: SampleCounts,
) -> list[str]:
    """The policy: why the estimate is of low confidence (empty: it is OK)."""
    warnings: list[str] = []
    deflection = figures.deflection[0]
    if not release.found:
        warnings.append(f'{release.message}; stiffness needs a release in the window')
    elif release.confidence < config.min_release_confidence:
        warnings.append(f'release uncertain (confidence {release.confidence:.2f})')
    if release.message and release.found:
        warnings.append(release.message)
    if release.found and math.isfinite(release.level_before_m) and not deflection > 0.0:
        warnings.append(f'the static tip level did not rise at the release ({deflection:.3g} m)')
    if figures.cycles < config.min_cycles:
        warnings.append(f'only {figures.cycles:.1f} cycles fitted')
    if tally.untrusted:
        warnings.append(
            f'{tally.note()} in the window, more than {MAX_DROPPED_FRACTION:.0%}: '
            'the poses may mix two streams'
        )
    relative = (
        ('frequency', mode.natural_frequency_hz, mode.natural_frequency_hz_std,
         config.warn_rel_std_frequency),
        ('damping ratio', mode.damping_ratio, mode.damping_ratio_std,
         config.warn_rel_std_damping),
        ('stiffness', figures.static.total_nm_per_rad, figures.static.total_nm_per_rad_std,
         config.warn_rel_std_stiffness),
    )  # fmt: skip
    for name, value, std, limit in relative:
        _check_rel(warnings, name, value, std, limit)
    pencil_zeta = checks.pencil[1]
    if math.isfinite(pencil_zeta):
        gap = abs(pencil_zeta - mode.damping_ratio) / mode.damping_ratio
        if gap > config.warn_cross_check_damping:
            warnings.append(
                f'matrix pencil damping ratio {pencil_zeta:.3g} disagrees with the fit '
                f'{mode.damping_ratio:.3g}'
            )
    return warnings


def _method(params: DampedSinusoidParameters) -> str:
    """The estimator's name: the fit, its modes and whether it was nonlinear."""
    method = METHOD if params.n_modes == 1 else f'{METHOD}_{params.n_modes}modes'
    return method + '_nonlinear' if params.nonlinear else method


def _report(
    status: Status,
    message: str,
    release: Release,
    state: FitState,
    mode: ModeEstimate,
    figures: Figures,
    span: AnalysedWindow,
    tally: SampleCounts,
) -> Identification:
    """The reporting: the figures in the groups of doc/interfaces.md."""
    params, checks = state.params, state.checks
    static = figures.static
    logdec = checks.logdec
    return Identification(
        status=status,
        message=message,
        method=_method(params),
        estimates=Estimates(
            natural_frequency_hz=Estimate(
                mode.natural_frequency_hz, mode.natural_frequency_hz_std
            ),
            damped_frequency_hz=Estimate(mode.damped_frequency_hz, mode.damped_frequency_hz_std),
            damping_ratio=Estimate(mode.damping_ratio, mode.damping_ratio_std),
            log_decrement=Estimate(mode.log_decrement, mode.log_decrement_std),
            stiffness_total_nm_per_rad=Estimate(
                static.total_nm_per_rad, static.total_nm_per_rad_std
            ),
            stiffness_vertical_n_per_m=Estimate(
                static.vertical_n_per_m, static.vertical_n_per_m_std
            ),
            damping_total=Estimate(*figures.damping_total),
        ),
        window=replace(span, cycles=figures.cycles),
        release=ReleaseFigures(
            time_s=Estimate(release.time_s, release.time_std_s),
            static_deflection_m=Estimate(*figures.deflection),
            confidence=release.confidence,
            source=release.source,
            released_load_kg=figures.load_kg,
            level_before_m=Estimate(release.level_before_m, release.level_before_std_m),
            level_after_m=Estimate(*figures.level_after),
        ),
        cross_checks=CrossCheckFigures(
            log_decrement_b20=Estimate(logdec.log_decrement, logdec.log_decrement_std)
            if logdec
            else UNKNOWN,
            damping_ratio_b20=Estimate(logdec.damping_ratio, logdec.damping_ratio_std)
            if logdec
            else UNKNOWN,
            damped_frequency_b20_hz=Estimate(
                logdec.damped_frequency_hz, logdec.damped_frequency_hz_std
            )
            if logdec
            else UNKNOWN,
            natural_frequency_pencil_hz=checks.pencil[0],
            damping_ratio_pencil=checks.pencil[1],
            stiffness_vertical_from_frequency_n_per_m=Estimate(*figures.stiffness_from_frequency),
            stiffness_total_from_pitch_nm_per_rad=Estimate(*checks.pitch_stiffness),
        ),
        quality=FitQuality(
            amplitude_m=mode.amplitude,
            residual_rms_m=params.residual_rms,
            covariance_inflation=params.covariance.inflation,
            second_mode_hz=_second_mode_hz(params),
            amplitude_frequency_shift_hz=params.frequency_shift_hz,
            amplitude_level_shift_m=params.level_shift_m,
            solver_evaluations=params.n_evaluations,
        ),
        samples=tally,
        modes=identified_modes(params),
    )


def _second_mode_hz(params: DampedSinusoidParameters) -> float:
    """Damped frequency of the second-lowest fitted mode (NaN with one mode)."""
    modes = identified_modes(params)
    if len(modes) < 2:
        return NAN
    mode = modes[1]
    f_n, zeta = mode.natural_frequency_hz.value, mode.damping_ratio.value
    return f_n * math.sqrt(1.0 - zeta * zeta)


def _check_rel(warnings: list[str], name: str, value: float, std: float, limit: float) -> None:
    if math.isfinite(value) and value != 0.0 and std / abs(value) > limit:
        warnings.append(f'{name} uncertain (relative std {std / abs(value):.2g})')
