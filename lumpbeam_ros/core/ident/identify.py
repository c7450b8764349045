"""Identification of one window of tip poses: the paper's section B.3.2, automated.

The steps: find the release (:mod:`~lumpbeam_ros.core.ident.release`); fit the free decay after
it by least squares (:class:`~lumpbeam_ros.core.ident.sinusoid.DampedSinusoidFit`), started from
the matrix pencil (:class:`~lumpbeam_ros.core.ident.pencil.MatrixPencil`), which also serves as a
cross-check; take k_tE from the static rise by B.12 and c_tE from the damping by B.22; add
the paper's own log decrement (B.20, B.21) for comparison; grade the result
(:mod:`~lumpbeam_ros.core.ident.assembly`).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from lumpbeam_ros.base.blas import single_threaded_blas
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident import stiffness
from lumpbeam_ros.core.ident.assembly import (
    NAN,
    CrossChecks,
    FitState,
    assemble,
    lowest_mode,
    released_load,
)
from lumpbeam_ros.core.ident.backbone import beam_backbone
from lumpbeam_ros.core.ident.identification import (
    AnalysedWindow,
    Estimate,
    Identification,
    ReleaseFigures,
    Status,
)
from lumpbeam_ros.core.ident.logdec import LogDecrement, LogDecrementResult
from lumpbeam_ros.core.ident.mode_estimate import TWO_PI, ModeEstimate
from lumpbeam_ros.core.ident.modes import choose_modes
from lumpbeam_ros.core.ident.outliers import without_spikes
from lumpbeam_ros.core.ident.pencil import MatrixPencil
from lumpbeam_ros.core.ident.release import Release, detect_release
from lumpbeam_ros.core.ident.ring_down import (
    RestTracker,
    min_rest_s,
    no_ring_down_message,
    swing_after,
)
from lumpbeam_ros.core.ident.samples import PoseWindow
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.ident.sinusoid import (
    DampedSinusoidFit,
    DampedSinusoidParameters,
    ModeGuess,
    ShiftPrior,
)
from lumpbeam_ros.core.ident.vetting import vetted
from lumpbeam_ros.core.model.parameters import BeamParameters

#: Grid points (after block averaging) the matrix pencil sees at most: 45 s at 90 Hz.
_PENCIL_MAX_POINTS = 4096
#: The starting pencil's order: the offset, two modes and a spare pair (further modes are
#: looked for in what the fit leaves, :mod:`~lumpbeam_ros.core.ident.modes`).
_PENCIL_ORDER = 7


def identify(
    window: PoseWindow,
    beam: BeamParameters,
    config: IdentifierConfig | None = None,
    *,
    strict: bool = False,
) -> Identification:
    """Identifies frequency, damping and stiffness from a window holding a load drop.

    Args:
        window: Cleaned tip poses (:func:`~lumpbeam_ros.core.ident.samples.clean_window` or
            :meth:`~lumpbeam_ros.core.ident.window.SlidingWindow.snapshot`), with the
            ``/tip_load`` readings if any.
        beam: Supplies L, g, m_b and m_d (for B.12 and the frequency cross-check).
        config: Settings (default: :class:`IdentifierConfig` defaults).
        strict: Raise on unusable input (a batch call) instead of returning ERROR (live).

    Returns:
        The identification; ``status`` ERROR when the window holds no oscillation.

    Raises:
        LumpbeamError: Only with ``strict``: too few valid samples in the window or after
            the release.
    """
    return identify_from(window, beam, config, strict=strict)[0]


def identify_from(
    window: PoseWindow,
    beam: BeamParameters,
    config: IdentifierConfig | None = None,
    *,
    strict: bool = False,
    previous: FitState | None = None,
    release: Release | None = None,
) -> tuple[Identification, FitState | None]:
    """:func:`identify`, started from the state of an earlier, overlapping window.

    With a ``previous`` state for the same release, checked less than
    ``fit.recheck_every_s`` ago, the least-squares fit starts from the previous solution
    and keeps its model (modes, nonlinear terms), and the cross-checks (matrix pencil, log
    decrement, pitch stiffness) are carried over instead of rerun: a live window that moved
    by a few samples converges in one or two solver steps. Otherwise (or when that fit
    fails) the full identification runs.

    Args:
        window: As for :func:`identify`.
        beam: As for :func:`identify`.
        config: As for :func:`identify`.
        strict: As for :func:`identify`.
        previous: The state the last call returned, or ``None``.
        release: Where the free vibration starts when it is known otherwise, e.g. where an
            arm's joints stopped (:func:`~lumpbeam_ros.core.ident.ring_down.ring_down_release`);
            ``None``: the load release found in the window.

    Returns:
        The identification, vetted (:func:`~lumpbeam_ros.core.ident.vetting.vetted`), and
        the state for the next call (``None`` after an ERROR).

    Raises:
        LumpbeamError: As for :func:`identify`.
    """
    with single_threaded_blas():
        result, state = _identify(
            window, beam, config or IdentifierConfig(), strict, previous, release
        )
    published = vetted(result)
    # A warm start that went wrong is not built on: the next window starts afresh.
    return published, state if published.status == result.status else None


def identify_live(
    window: PoseWindow,
    beam: BeamParameters,
    config: IdentifierConfig,
    previous: FitState | None,
    joints: RestTracker,
) -> tuple[Identification, FitState | None]:
    """One update of the live identifier: never raises, an ERROR says why not.

    A beam's window is identified whole; once ``/joint_states`` have been seen (an arm), only
    the free vibration after the joints' last stop, along the tip's swing, and nothing until
    the joints have rested for ``quality.min_samples`` poses.

    Args:
        window: The sliding window's snapshot.
        beam: As :func:`identify`.
        config: Settings.
        previous: The last update's fit, to start from (``None``: a full identification).
        joints: The joints' rests, as received live.

    Returns:
        The identification and the fit the next update starts from.
    """
    release = None
    if joints.current is not None:
        rest = joints.ring_down(min_rest_s(window, config.min_samples))
        if rest is None:
            return Identification(
                Status.ERROR, no_ring_down_message(config.rest_tolerance_rad)
            ), None
        window, release = swing_after(window, rest)
    try:
        return identify_from(window, beam, config, previous=previous, release=release)
    except (LumpbeamError, ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:
        # Numerically hopeless windows (e.g. a constant signal) give no estimate.
        return Identification(Status.ERROR, f'identification failed: {exc}'), None


def _identify(
    window: PoseWindow,
    beam: BeamParameters,
    config: IdentifierConfig,
    strict: bool,
    previous: FitState | None,
    given: Release | None = None,
) -> tuple[Identification, FitState | None]:
    span = AnalysedWindow(window.start_s, window.end_s)
    window = without_spikes(window)
    dropped = window.counts.dropped
    tally = replace(window.counts, received=len(window) + dropped)

    def fail(
        message: str, unusable: bool = False, release: ReleaseFigures | None = None
    ) -> tuple[Identification, None]:
        if strict and unusable:
            raise LumpbeamError(message)
        figures = release or ReleaseFigures()
        return Identification(
            Status.ERROR, message, window=span, release=figures, samples=tally
        ), None

    if len(window) < config.min_samples:
        return fail(
            f'{len(window)} valid pose samples, need at least {config.min_samples}',
            unusable=True,
        )
    release = detect_release(window, config) if given is None else given
    found = ReleaseFigures(
        time_s=Estimate(release.time_s), confidence=release.confidence, source=release.source
    )
    start = window.start_s
    if release.found and release.time_s >= window.start_s:
        start = release.time_s + config.skip_after_release_s
        if math.isfinite(release.decay_start_s):
            start = max(start, release.decay_start_s)
    end = min(start + config.max_fit_s, release.decay_end_s)
    keep = (window.t >= start) & (window.t <= end)
    t, z = window.t[keep], window.z[keep]
    if t.size < config.min_samples:
        return fail(
            f'{t.size} pose samples after the release at {release.time_s:.3f} s, need '
            f'{config.min_samples}',
            unusable=True,
            release=found,
        )
    prior = _shift_prior(beam, config) if given is None else None
    state = _warm_fit(t, z, start, release, previous, config, prior)
    if state is None:
        guesses = _initial_modes(t, z, config)
        if not guesses:
            return fail('no oscillation in the window', release=found)
        try:
            params = _fit_decay(t, z, guesses, start, config, prior)
        except LumpbeamError as exc:
            return fail(f'no oscillation in the window ({exc})', release=found)
        rejection = _reject_mode(params.mode(lowest_mode(params)), params, config)
        if rejection:
            return fail(rejection, release=found)
        checks = CrossChecks(
            _pencil_first(guesses),
            _log_decrement(t, z, params),
            _pitch_stiffness(
                window, release, params, float(t[-1]), released_load(release, config), beam
            ),
        )
        state = FitState(release.time_s, params, checks, window.end_s)
    mode = state.params.mode(lowest_mode(state.params))
    rejection = _reject_mode(mode, state.params, config)
    if rejection:
        return fail(rejection, release=found)
    result = assemble(beam, config, release, t, state, mode, span, tally)
    return result, state


def _same_release(a: float, b: float) -> bool:
    """Whether two release times (NaN: none) are the same event, to a few milliseconds."""
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return abs(a - b) < 0.02


def _warm_fit(
    t: np.ndarray,
    z: np.ndarray,
    start: float,
    release: Release,
    previous: FitState | None,
    config: IdentifierConfig,
    prior: ShiftPrior | None,
) -> FitState | None:
    """The fit restarted from ``previous``, or ``None`` when a full identification is due.

    It keeps the previous model, but for the nonlinear terms: a decay that has grown long
    enough for them since (:func:`_wants_nonlinear`) gets them, held to ``prior``, or its
    frequency would keep the linear model's amplitude-averaged bias until the next check.
    """
    if previous is None or not _same_release(previous.release_time_s, release.time_s):
        return None
    if t[-1] - previous.checked_at_s >= config.recheck_every_s:
        return None
    old = previous.params
    first = old.mode(0)
    guess = (first.damped_frequency_hz, first.damping_ratio)
    nonlinear = old.nonlinear or _wants_nonlinear(guess, t[-1] - start, config)
    fit = DampedSinusoidFit(old.n_modes, old.drift, nonlinear=nonlinear, shift_prior=prior)
    try:
        params = fit.fit(t, z, t0=start, start=old)
    except LumpbeamError:
        return None
    return FitState(release.time_s, params, previous.checks, previous.checked_at_s)


def _initial_modes(t: np.ndarray, z: np.ndarray, config: IdentifierConfig) -> list[ModeGuess]:
    """The starting mode from the matrix pencil: the strongest in band (or none)."""
    rate = 1.0 / float(np.median(np.diff(t)))
    # Block means down to 2.25 samples per period of the highest frequency of interest:
    # below Nyquist with a margin, and a quarter of the pencil's cost at 180 Hz.
    decimation = max(1, int(rate / (2.25 * config.max_frequency_hz)))
    # The pencil only starts the fit and cross-checks it: the head of a long record will do.
    head = slice(0, _PENCIL_MAX_POINTS * decimation)
    try:
        pencil = MatrixPencil(order=_PENCIL_ORDER, decimation=decimation).fit(t[head], z[head])
    except LumpbeamError:
        return []
    in_band = [
        m
        for m in pencil.modes
        if config.min_frequency_hz <= m.damped_frequency_hz <= config.max_frequency_hz
        and 0.0 < m.damping_ratio < 0.5
    ]
    if not in_band:
        return []
    first = in_band[0]
    return [(first.damped_frequency_hz, first.damping_ratio)]


def _shift_prior(beam: BeamParameters, config: IdentifierConfig) -> ShiftPrior | None:
    """The beam's backbone as the prior of the frequency shift, or ``None``.

    ``None`` when the prior is switched off or the model has no backbone (a beam without
    gravity cannot be dropped): the shift is then fitted freely. Only for a beam's load
    release: an arm's ring-down is another structure than the configured beam.
    """
    if config.shift_prior_std == 0.0:
        return None
    try:
        backbone = beam_backbone(beam)
    except LumpbeamError:
        return None
    return ShiftPrior(backbone.relative_per_m2, config.shift_prior_std)


def _fit_decay(
    t: np.ndarray,
    z: np.ndarray,
    guesses: list[ModeGuess],
    start: float,
    config: IdentifierConfig,
    prior: ShiftPrior | None = None,
) -> DampedSinusoidParameters:
    """The least-squares decay, with the modes and nonlinear terms the data support.

    The strongest mode first, with its nonlinear terms when :func:`_wants_nonlinear` (their
    frequency shift held to ``prior``); then each further mode that stands out of the noise
    (:func:`~lumpbeam_ros.core.ident.modes.choose_modes`).
    """
    nonlinear = _wants_nonlinear(guesses[0], t[-1] - start, config)
    fit = DampedSinusoidFit(n_modes=1, drift=config.drift, nonlinear=nonlinear, shift_prior=prior)
    params = fit.fit(t, z, initial=guesses[:1], t0=start)
    if config.max_modes > 1 and params.mode(0).decay_rate > 0.0:
        params = choose_modes(t, z, params, config).params
    return params


def _wants_nonlinear(first: ModeGuess, span_s: float, config: IdentifierConfig) -> bool:
    """Whether to fit the first mode's amplitude-dependent level and frequency.

    ``auto`` fits them when they are identifiable: they decay as ``e^{-2 sigma tau}``, and
    over a stretch T with ``2 sigma T`` small that is nearly ``1 - 2 sigma tau``, collinear
    with the level and the frequency. A significance test of the terms would not do: a
    linear fit's frequency is biased by many of its own (small) standard deviations long
    before the terms are significant against the nonlinear fit's (large) ones. The decay
    rate comes from the matrix pencil's start, so one fit suffices.
    """
    if config.nonlinear != 'auto':
        return config.nonlinear == 'always'
    f_d, zeta = first
    decay_rate = zeta * TWO_PI * f_d / math.sqrt(max(1.0 - zeta * zeta, 1e-12))
    return 2.0 * decay_rate * span_s >= config.nonlinear_min_decay


def _reject_mode(
    mode: ModeEstimate, params: DampedSinusoidParameters, config: IdentifierConfig
) -> str:
    """Why the fitted first mode is not an oscillation of the beam, or ``''``."""
    snr = mode.amplitude / max(params.residual_rms, 1e-15)
    if snr < config.min_amplitude_snr:
        return f'no oscillation in the window (amplitude {snr:.1f} x the residual noise)'
    if not config.min_frequency_hz <= mode.damped_frequency_hz <= config.max_frequency_hz:
        return (
            f'no oscillation in the window (fitted {mode.damped_frequency_hz:.3g} Hz is '
            f'outside {config.min_frequency_hz:g}..{config.max_frequency_hz:g} Hz)'
        )
    if not mode.damping_ratio > 0.0:
        return 'no free decay in the window: the oscillation grows'
    return ''


def _pencil_first(guesses: list[ModeGuess]) -> tuple[float, float]:
    """Natural frequency and damping ratio of the pencil's first mode (the fit's start)."""
    f_d, zeta = guesses[0]
    return f_d / math.sqrt(1.0 - zeta * zeta), zeta


def _log_decrement(
    t: np.ndarray, z: np.ndarray, params: DampedSinusoidParameters
) -> LogDecrementResult | None:
    """The paper's B.20/B.21 on the same stretch, about the fitted level; None if it fails."""
    try:
        return LogDecrement().fit(t, z, offset=params.offset, noise_std=params.residual_rms)
    except LumpbeamError:
        return None


def _pitch_stiffness(
    window: PoseWindow,
    release: Release,
    params: DampedSinusoidParameters,
    end: float,
    load: float,
    beam: BeamParameters,
) -> tuple[float, float]:
    """k_tE from the fall of the static pitch (slope form of B.12), as a cross-check."""
    if not math.isfinite(release.pitch_before_rad):
        return NAN, NAN
    keep = (window.t >= params.t0) & (window.t <= end)
    pitch = window.pitch[keep]
    if pitch.size < 10 or not np.all(np.isfinite(pitch)):
        return NAN, NAN
    after, after_std = params.offset_of(window.t[keep], pitch)
    change = release.pitch_before_rad - after
    change_std = math.hypot(after_std, release.pitch_before_std_rad)
    return stiffness.from_pitch_change(change, change_std, load, beam.length_m, beam.gravity_mps2)
