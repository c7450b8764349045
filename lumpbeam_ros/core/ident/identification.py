"""The identification result: doc/interfaces.md (``/beam_params`` and ``lumpbeam analyze``).

Each figure is an :class:`Estimate` (value, std); :class:`Identification` groups them with
the release, the window and the fit's quality, and flattens them to the contract's keys.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field, fields, is_dataclass
from enum import IntEnum
from typing import Any

from lumpbeam_ros.core.bagio.tipseries import SampleCounts

NAN = float('nan')


class Status(IntEnum):
    """Confidence of an estimate; the values are diagnostic_msgs/DiagnosticStatus levels."""

    OK = 0
    WARN = 1
    ERROR = 2


@dataclass(frozen=True)
class Estimate:
    """An identified figure and its standard deviation (NaN: not determined).

    Attributes:
        value: The figure.
        std: Its standard deviation (the ``<key>_std`` of doc/interfaces.md).
    """

    value: float = NAN
    std: float = NAN


UNKNOWN = Estimate()


def _key(name: str, default: Any = UNKNOWN) -> Any:
    """A field published as ``name`` (and ``name_std`` for an :class:`Estimate`)."""
    return field(default=default, metadata={'key': name})


@dataclass(frozen=True)
class Estimates:
    """The first mode's figures and the stiffness from the release (doc/interfaces.md).

    Attributes:
        natural_frequency_hz: f_n = f_d / sqrt(1 - zeta^2).
        damped_frequency_hz: f_d.
        damping_ratio: zeta, from the least-squares decay fit.
        log_decrement: delta = 2 pi sigma / omega_d, consistent with zeta by B.21.
        stiffness_total_nm_per_rad: k_tE = 2 F L^2 / (3 delta_vE) (B.12).
        stiffness_vertical_n_per_m: F / delta_vE.
        damping_total: c_tE = 2 zeta omega_d (B.22).
    """

    natural_frequency_hz: Estimate = UNKNOWN
    damped_frequency_hz: Estimate = UNKNOWN
    damping_ratio: Estimate = UNKNOWN
    log_decrement: Estimate = UNKNOWN
    stiffness_total_nm_per_rad: Estimate = UNKNOWN
    stiffness_vertical_n_per_m: Estimate = UNKNOWN
    damping_total: Estimate = UNKNOWN


@dataclass(frozen=True)
class AnalysedWindow:
    """The stretch of poses analysed.

    Attributes:
        start_s: First stamp analysed (``window_start_s``).
        end_s: Last stamp analysed (``window_end_s``).
        cycles: Damped periods in the fitted stretch.
    """

    start_s: float = _key('window_start_s', NAN)
    end_s: float = _key('window_end_s', NAN)
    cycles: float = 0.0


@dataclass(frozen=True)
class ReleaseFigures:
    """The release of the load and the static levels around it.

    Attributes:
        time_s: When the load left (NaN when not in the window), from the onset of the free
            response in the tip poses, with its std from the onset fit (``release_time_s``).
        static_deflection_m: delta_vE, the rise of the static tip level at the release.
        confidence: 0..1 (``release_confidence``).
        source: ``tip_load``, ``data``, ``none``, or ``joint_states`` for an arm's ring-down
            (``release_source``).
        released_load_kg: F / g used in B.12.
        level_before_m: Static tip z before the release.
        level_after_m: The level the decay converges to.
    """

    time_s: Estimate = _key('release_time_s')
    static_deflection_m: Estimate = UNKNOWN
    confidence: float = _key('release_confidence', 0.0)
    source: str = _key('release_source', 'none')
    released_load_kg: float = NAN
    level_before_m: Estimate = UNKNOWN
    level_after_m: Estimate = UNKNOWN


@dataclass(frozen=True)
class CrossCheckFigures:
    """The same figures by other estimators, to check the fit against.

    Attributes:
        log_decrement_b20: delta by the paper's two-peak rule (B.20).
        damping_ratio_b20: zeta from it by B.21.
        damped_frequency_b20_hz: f_d from the peak times.
        natural_frequency_pencil_hz: f_n by the matrix pencil.
        damping_ratio_pencil: zeta by the matrix pencil.
        stiffness_vertical_from_frequency_n_per_m: m_eff (2 pi f_n)^2 with
            m_eff = m_tip + fraction * m_beam (model uncertainty not included).
        stiffness_total_from_pitch_nm_per_rad: k_tE = F L / delta_thetaE, the slope form of
            B.12.
    """

    log_decrement_b20: Estimate = UNKNOWN
    damping_ratio_b20: Estimate = UNKNOWN
    damped_frequency_b20_hz: Estimate = UNKNOWN
    natural_frequency_pencil_hz: float = NAN
    damping_ratio_pencil: float = NAN
    stiffness_vertical_from_frequency_n_per_m: Estimate = UNKNOWN
    stiffness_total_from_pitch_nm_per_rad: Estimate = UNKNOWN


@dataclass(frozen=True)
class FitQuality:
    """How well the decay model fits, and what else it found.

    Attributes:
        amplitude_m: Amplitude of the first mode at the start of the fit.
        residual_rms_m: RMS of the fit residuals.
        covariance_inflation: Robust over white-noise variance (>1: correlated residuals).
        second_mode_hz: Damped frequency of a fitted second mode (NaN when not fitted).
        amplitude_frequency_shift_hz: How much faster the first mode ran at the start of the
            fit than at small amplitude (0 when the nonlinear terms were not fitted).
        amplitude_level_shift_m: How far the oscillation's centre was above the equilibrium
            at the start of the fit (0 likewise).
        solver_evaluations: Model evaluations of the least-squares solver.
    """

    amplitude_m: float = NAN
    residual_rms_m: float = NAN
    covariance_inflation: float = NAN
    second_mode_hz: float = NAN
    amplitude_frequency_shift_hz: float = NAN
    amplitude_level_shift_m: float = NAN
    solver_evaluations: int = 0


@dataclass(frozen=True)
class IdentifiedMode:
    """One damped mode of the free vibration: an entry of ``modes`` (doc/interfaces.md).

    Attributes:
        natural_frequency_hz: f_n = f_d / sqrt(1 - zeta^2), with its std.
        damping_ratio: zeta, with its std.
        amplitude_m: The mode's amplitude in the tip position at the start of the fit.
    """

    natural_frequency_hz: Estimate = UNKNOWN
    damping_ratio: Estimate = UNKNOWN
    amplitude_m: float = NAN

    def as_dict(self) -> dict[str, float]:
        """The mode as ``lumpbeam analyze`` lists it in ``modes``."""
        return {
            'natural_frequency_hz': self.natural_frequency_hz.value,
            'natural_frequency_hz_std': self.natural_frequency_hz.std,
            'damping_ratio': self.damping_ratio.value,
            'damping_ratio_std': self.damping_ratio.std,
            'amplitude_m': self.amplitude_m,
        }


#: The ``/beam_params`` key of the number of modes; mode k >= 2 is published under
#: ``mode_<k>_`` + each key of :data:`MODE_KEYS` (and its ``_std``).
MODE_COUNT_KEY = 'mode_count'
MODE_KEYS = ('natural_frequency_hz', 'damping_ratio')


def mode_key(k: int, key: str) -> str:
    """The ``/beam_params`` key of mode ``k`` (1-based, k >= 2), e.g. ``mode_2_damping_ratio``."""
    return f'mode_{k}_{key}'


def _mode_pairs(modes: tuple[IdentifiedMode, ...]) -> Iterator[tuple[str, str]]:
    """``mode_count`` and, for k >= 2, each mode's frequency and damping with their stds."""
    yield MODE_COUNT_KEY, str(len(modes))
    for k, mode in enumerate(modes[1:], start=2):
        for key in MODE_KEYS:
            estimate = getattr(mode, key)
            yield mode_key(k, key), repr(float(estimate.value))
            yield mode_key(k, f'{key}_std'), repr(float(estimate.std))


def _flat(group: Any) -> Iterator[tuple[str, Any]]:
    """A group's ``(key, value)`` pairs in field order; an estimate gives two."""
    for f in fields(group):
        value = getattr(group, f.name)
        key = f.metadata.get('key', f.name)
        if isinstance(value, SampleCounts):
            yield 'n_samples', value.n_samples
            yield 'n_rejected', value.n_rejected
        elif isinstance(value, Estimate):
            yield key, value.value
            yield f'{key}_std', value.std
        elif is_dataclass(value) and not isinstance(value, type):
            yield from _flat(value)
        else:
            yield key, value


def _plain(value: Any) -> Any:
    """A flat value as JSON wants it: a status by its name, the modes as a list."""
    if isinstance(value, Status):
        return value.name
    if isinstance(value, tuple):
        return [mode.as_dict() for mode in value]
    return value


@dataclass(frozen=True)
class Identification:
    """Frequency, damping and stiffness identified from one window, each with its std.

    The flat keys of doc/interfaces.md are the groups' fields in order (an
    :class:`Estimate` ``<key>`` gives ``<key>`` and ``<key>_std``); NaN marks a figure the
    window does not determine (e.g. no stiffness without a release in it). Paper equation
    numbers: B.12 (stiffness), B.20 and B.21 (decrement and damping ratio), B.22 (total
    damping).

    Attributes:
        status: OK, WARN (low confidence) or ERROR (no oscillation, no estimate).
        message: Human-readable reason for the status.
        method: The estimator behind the headline figures.
        estimates: The headline figures.
        window: The stretch analysed.
        release: The release and the static levels.
        cross_checks: The figures by other estimators.
        quality: The fit's quality.
        samples: The window's samples: its poses kept and those dropped (published as
            ``n_samples`` and ``n_rejected``).
        modes: Every mode separated from the noise, ordered by frequency (the first is the
            one of :attr:`estimates`); ``modes`` in JSON, ``mode_count`` and ``mode_<k>_*``
            on ``/beam_params``.
    """

    status: Status
    message: str
    method: str = 'none'
    estimates: Estimates = Estimates()
    window: AnalysedWindow = AnalysedWindow()
    release: ReleaseFigures = ReleaseFigures()
    cross_checks: CrossCheckFigures = CrossCheckFigures()
    quality: FitQuality = FitQuality()
    samples: SampleCounts = SampleCounts()
    modes: tuple[IdentifiedMode, ...] = ()

    @property
    def ok(self) -> bool:
        """Whether the estimate is valid (status OK or WARN)."""
        return self.status != Status.ERROR

    def as_dict(self) -> dict[str, Any]:
        """Returns every field by its key; ``status`` as its name (``'OK'``...).

        NaN stays NaN (``lumpbeam_ros.apps.cli.output.write_json`` turns it into null);
        ``modes`` is a list of :meth:`IdentifiedMode.as_dict`, ordered by frequency.
        """
        return {key: _plain(value) for key, value in _flat(self)}

    def figure(self, key: str) -> Estimate:
        """The figure published as ``key``, with its ``key_std`` (NaN when it has none).

        Args:
            key: A key of doc/interfaces.md, e.g. ``'natural_frequency_hz'``.

        Returns:
            The value and std.

        Raises:
            KeyError: No numeric figure has that key.
        """
        data = self.as_dict()
        value = data[key]
        if isinstance(value, str):
            raise KeyError(key)
        return Estimate(float(value), float(data.get(f'{key}_std', NAN)))

    def key_values(self) -> list[tuple[str, str]]:
        """The ``/beam_params`` KeyValue pairs: floats as Python ``repr`` (doc/interfaces.md).

        ``status`` and ``message`` are left out: they are the DiagnosticStatus's own level
        and message. Strings (``method``, ``release_source``) are given as they are.
        """
        pairs: list[tuple[str, str]] = []
        for key, value in _flat(self):
            if key == 'modes':
                pairs.extend(_mode_pairs(value))
            elif key not in ('status', 'message'):
                pairs.append((key, value if isinstance(value, str) else repr(float(value))))
        return pairs

    def summary(self) -> str:
        """A few human-readable lines for a terminal."""

        def fmt(estimate: Estimate, unit: str, digits: int = 5) -> str:
            if not math.isfinite(estimate.value):
                return 'n/a'
            return f'{estimate.value:.{digits}g} +- {estimate.std:.2g} {unit}'

        figures, release = self.estimates, self.release
        return '\n'.join(
            [
                f'status: {self.status.name} {self.message}'.rstrip(),
                f'release: {release.time_s.value:.4f} s ({release.source}, '
                f'confidence {release.confidence:.2f})',
                'natural frequency: ' + fmt(figures.natural_frequency_hz, 'Hz'),
                'damping ratio: ' + fmt(figures.damping_ratio, ''),
                'static deflection: ' + fmt(release.static_deflection_m, 'm'),
                'k_tE (B.12): ' + fmt(figures.stiffness_total_nm_per_rad, 'N m/rad'),
                'c_tE (B.22): ' + fmt(figures.damping_total, '1/s'),
            ]
        )
