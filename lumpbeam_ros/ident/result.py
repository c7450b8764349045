"""The identification result: doc/interfaces.md (``/beam_params``) and section 5 (``analyze``)."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from enum import IntEnum
from typing import Any

NAN = float('nan')


class Status(IntEnum):
    """Confidence of an estimate; the values are diagnostic_msgs/DiagnosticStatus levels."""

    OK = 0
    WARN = 1
    ERROR = 2


@dataclass(frozen=True)
class Identification:
    """Frequency, damping and stiffness identified from one window, each with its std.

    Keys follow doc/interfaces.md; a ``<key>_std`` field is the standard deviation of
    ``<key>``. NaN marks a figure the window does not determine (e.g. no stiffness without a
    release in it). Paper equation numbers: B.12 (stiffness), B.20 and B.21 (decrement and
    damping ratio), B.22 (total damping).

    Attributes:
        status: OK, WARN (low confidence) or ERROR (no oscillation, no estimate).
        message: Human-readable reason for the status.
        method: The estimator behind the headline figures.
        natural_frequency_hz: f_n = f_d / sqrt(1 - zeta^2) of the first mode.
        damped_frequency_hz: f_d of the first mode.
        damping_ratio: zeta of the first mode, from the least-squares decay fit.
        log_decrement: delta = 2 pi sigma / omega_d, consistent with zeta by B.21.
        stiffness_total_nm_per_rad: k_tE = 2 F L^2 / (3 delta_vE) (B.12).
        stiffness_vertical_n_per_m: F / delta_vE.
        damping_total: c_tE = 2 zeta omega_d (B.22).
        window_start_s: First stamp analysed.
        window_end_s: Last stamp analysed.
        cycles: Damped periods in the fitted stretch.
        release_time_s: When the load left (NaN when not in the window), from the onset of
            the free response in the tip poses.
        release_time_s_std: Its standard deviation from the onset fit.
        static_deflection_m: delta_vE, the rise of the static tip level at the release.
        release_confidence: 0..1.
        release_source: ``tip_load``, ``data`` or ``none``.
        released_load_kg: F / g used in B.12.
        level_before_m: Static tip z before the release.
        level_after_m: The level the decay converges to.
        log_decrement_b20: delta by the paper's two-peak rule (B.20).
        damping_ratio_b20: zeta from it by B.21.
        damped_frequency_b20_hz: f_d from the peak times.
        natural_frequency_pencil_hz: f_n by the matrix pencil (cross-check).
        damping_ratio_pencil: zeta by the matrix pencil (cross-check).
        stiffness_vertical_from_frequency_n_per_m: m_eff (2 pi f_n)^2 with
            m_eff = m_tip + fraction * m_beam (cross-check; model uncertainty not included).
        stiffness_total_from_pitch_nm_per_rad: k_tE = F L / delta_thetaE, the slope form of
            B.12 (cross-check).
        amplitude_m: Amplitude of the first mode at the start of the fit.
        residual_rms_m: RMS of the fit residuals.
        covariance_inflation: Robust over white-noise variance (>1: correlated residuals).
        second_mode_hz: Damped frequency of a fitted second mode (NaN when not fitted).
        amplitude_frequency_shift_hz: How much faster the first mode ran at the start of the
            fit than at small amplitude (0 when the nonlinear terms were not fitted).
        amplitude_level_shift_m: How far the oscillation's centre was above the equilibrium
            at the start of the fit (0 likewise).
        solver_evaluations: Model evaluations of the least-squares solver.
        n_samples: Valid samples in the window.
        n_rejected: Samples dropped as non-finite or duplicate.
    """

    status: Status
    message: str
    method: str = 'none'
    natural_frequency_hz: float = NAN
    natural_frequency_hz_std: float = NAN
    damped_frequency_hz: float = NAN
    damped_frequency_hz_std: float = NAN
    damping_ratio: float = NAN
    damping_ratio_std: float = NAN
    log_decrement: float = NAN
    log_decrement_std: float = NAN
    stiffness_total_nm_per_rad: float = NAN
    stiffness_total_nm_per_rad_std: float = NAN
    stiffness_vertical_n_per_m: float = NAN
    stiffness_vertical_n_per_m_std: float = NAN
    damping_total: float = NAN
    damping_total_std: float = NAN
    window_start_s: float = NAN
    window_end_s: float = NAN
    cycles: float = 0.0
    release_time_s: float = NAN
    release_time_s_std: float = NAN
    static_deflection_m: float = NAN
    static_deflection_m_std: float = NAN
    release_confidence: float = 0.0
    release_source: str = 'none'
    released_load_kg: float = NAN
    level_before_m: float = NAN
    level_before_m_std: float = NAN
    level_after_m: float = NAN
    level_after_m_std: float = NAN
    log_decrement_b20: float = NAN
    log_decrement_b20_std: float = NAN
    damping_ratio_b20: float = NAN
    damping_ratio_b20_std: float = NAN
    damped_frequency_b20_hz: float = NAN
    damped_frequency_b20_hz_std: float = NAN
    natural_frequency_pencil_hz: float = NAN
    damping_ratio_pencil: float = NAN
    stiffness_vertical_from_frequency_n_per_m: float = NAN
    stiffness_vertical_from_frequency_n_per_m_std: float = NAN
    stiffness_total_from_pitch_nm_per_rad: float = NAN
    stiffness_total_from_pitch_nm_per_rad_std: float = NAN
    amplitude_m: float = NAN
    residual_rms_m: float = NAN
    covariance_inflation: float = NAN
    second_mode_hz: float = NAN
    amplitude_frequency_shift_hz: float = NAN
    amplitude_level_shift_m: float = NAN
    solver_evaluations: int = 0
    n_samples: int = 0
    n_rejected: int = 0

    @property
    def ok(self) -> bool:
        """Whether the estimate is valid (status OK or WARN)."""
        return self.status != Status.ERROR

    def as_dict(self) -> dict[str, Any]:
        """Returns every field by its key; ``status`` as its name (``'OK'``...).

        NaN stays NaN (``lumpbeam_ros.cli.output.write_json`` turns it into null).
        """
        out: dict[str, Any] = {}
        for f in fields(self):
            value = getattr(self, f.name)
            out[f.name] = value.name if isinstance(value, Status) else value
        return out

    def key_values(self) -> list[tuple[str, str]]:
        """The ``/beam_params`` KeyValue pairs: floats as Python ``repr`` (doc/interfaces.md).

        ``status`` and ``message`` are left out: they are the DiagnosticStatus's own level
        and message. Strings (``method``, ``release_source``) are given as they are.
        """
        pairs = []
        for f in fields(self):
            if f.name in ('status', 'message'):
                continue
            value = getattr(self, f.name)
            text = value if isinstance(value, str) else repr(float(value))
            pairs.append((f.name, text))
        return pairs

    def summary(self) -> str:
        """A few human-readable lines for a terminal."""

        def fmt(value: float, std: float, unit: str, digits: int = 5) -> str:
            if not math.isfinite(value):
                return 'n/a'
            return f'{value:.{digits}g} +- {std:.2g} {unit}'

        return '\n'.join(
            [
                f'status: {self.status.name} {self.message}'.rstrip(),
                f'release: {self.release_time_s:.4f} s ({self.release_source}, '
                f'confidence {self.release_confidence:.2f})',
                'natural frequency: '
                + fmt(self.natural_frequency_hz, self.natural_frequency_hz_std, 'Hz'),
                'damping ratio: ' + fmt(self.damping_ratio, self.damping_ratio_std, ''),
                'static deflection: '
                + fmt(self.static_deflection_m, self.static_deflection_m_std, 'm'),
                'k_tE (B.12): '
                + fmt(
                    self.stiffness_total_nm_per_rad,
                    self.stiffness_total_nm_per_rad_std,
                    'N m/rad',
                ),
                'c_tE (B.22): ' + fmt(self.damping_total, self.damping_total_std, '1/s'),
            ]
        )
