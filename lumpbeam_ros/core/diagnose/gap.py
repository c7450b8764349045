"""The gap between a simulation and a measurement: residual size, frequency and damping errors."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.diagnose.measurement import Record
from lumpbeam_ros.core.ident.mode_estimate import ModeEstimate
from lumpbeam_ros.core.ident.sinusoid import DampedSinusoidFit, DampedSinusoidParameters
from lumpbeam_ros.core.model.trajectory import TipTrajectory

#: Time after a load event before the decay fit starts: the higher modes (20 Hz and up,
#: damped ten times faster) have faded by then, so one damped mode describes the rest.
SETTLE_S = 0.3


@dataclass(frozen=True)
class Gap:
    """How far a model is from the measurement (doc/interfaces.md, ``gap_before``/``gap_after``).

    Attributes:
        rms_m: RMS of the tip-z residual over the record, m.
        max_m: Largest absolute tip-z residual, m.
        frequency_error: Relative error of the model's first-mode frequency after the load
            event, ``(f_model - f_measured) / f_measured``.
        damping_error: Relative error of its damping ratio, same convention.
    """

    rms_m: float
    max_m: float
    frequency_error: float
    damping_error: float

    def as_dict(self) -> dict[str, float]:
        """The JSON form."""
        return asdict(self)


def decay_fit(t: np.ndarray, z: np.ndarray, start_s: float) -> DampedSinusoidParameters:
    """A one-mode damped-sinusoid fit of the free decay after ``start_s``.

    Args:
        t: Stamps, s.
        z: Tip z, m.
        start_s: When the decay starts (a load event).

    Returns:
        The fit: its offset is the level the decay settles to.

    Raises:
        LumpbeamError: Too few samples or the fit failed.
    """
    keep = t >= start_s + SETTLE_S
    return DampedSinusoidFit(n_modes=1).fit(t[keep], z[keep], t0=start_s)


def decay_mode(t: np.ndarray, z: np.ndarray, start_s: float) -> ModeEstimate:
    """The first mode of the free decay after ``start_s`` (a damped-sinusoid fit of z).

    Args:
        t: Stamps, s.
        z: Tip z, m.
        start_s: When the decay starts (a load event).

    Returns:
        The fitted mode: frequency and damping ratio (an average one for a decay that is
        not exponential).

    Raises:
        LumpbeamError: Too few samples or the fit failed.
    """
    return decay_fit(t, z, start_s).mode(0)


def measure_gap(record: Record, model: TipTrajectory, measured_mode: ModeEstimate) -> Gap:
    """Compares a simulation at the record's stamps with the record.

    Args:
        record: The measurement.
        model: The simulated trajectory at the same stamps.
        measured_mode: :func:`decay_mode` of the measurement (computed once per record).

    Returns:
        The gap.
    """
    residual = model.z - record.z
    try:
        mode = decay_mode(model.t, model.z, record.event_time_s)
        f_err = mode.natural_frequency_hz / measured_mode.natural_frequency_hz - 1.0
        d_err = mode.damping_ratio / measured_mode.damping_ratio - 1.0
    except LumpbeamError:
        f_err = d_err = float('nan')
    return Gap(
        rms_m=float(np.sqrt(np.mean(residual**2))),
        max_m=float(np.max(np.abs(residual))),
        frequency_error=float(f_err),
        damping_error=float(d_err),
    )
