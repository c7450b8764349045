"""The last check before an identification is published: no confident unphysical mode.

Whatever path made it (a full identification or a warm start from the last window), a mode
reported at OK or WARN must be one a free decay can have, with an uncertainty the data can
give:

- a damping ratio confidently below 0 (by more than its standard deviation) is a mode that
  grows: a free decay has none (a warm start reported -0.00052 +- 4.9e-9 on a tap's tail);
- from data with noise (fit residuals above :data:`NOISE_FLOOR_M`) every estimate has an
  uncertainty: a frequency's standard deviation under :data:`MIN_RELATIVE_STD` of it, or a
  damping ratio's under :data:`MIN_DAMPING_STD`, is the estimator's defect, not a
  measurement (20.91 +- 1.9e-11 Hz came out of a 700 Hz record's noise).

A first mode that fails makes the whole identification an ERROR that says why, its figures
withheld; a higher mode that fails is left out, the message saying so.
"""

from __future__ import annotations

import math
from dataclasses import replace

from lumpbeam_ros.core.ident.identification import (
    Estimates,
    Identification,
    IdentifiedMode,
    Status,
)

#: Fit residuals above this RMS mean the data carry noise (noiseless synthetic data leave
#: round-off, 1e-12 m; no sensor is that quiet), m.
NOISE_FLOOR_M = 1e-9
#: The smallest relative standard deviation of a frequency from noisy data.
MIN_RELATIVE_STD = 1e-9
#: The smallest standard deviation of a damping ratio from noisy data.
MIN_DAMPING_STD = 1e-9


def mode_defect(mode: IdentifiedMode, residual_rms_m: float) -> str | None:
    """Why a mode may not be published, or ``None``.

    Args:
        mode: The mode.
        residual_rms_m: The fit's residual RMS, m (the data's noise).
    """
    f, f_std = mode.natural_frequency_hz.value, mode.natural_frequency_hz.std
    zeta, zeta_std = mode.damping_ratio.value, mode.damping_ratio.std
    if not all(math.isfinite(v) for v in (f, f_std, zeta, zeta_std)) or f <= 0.0:
        return f'{f!r} +- {f_std!r} Hz, damping ratio {zeta!r} +- {zeta_std!r}: not a mode'
    if zeta < 0.0 and zeta_std < -zeta:
        return f'damping ratio {zeta:.3g} +- {zeta_std:.2g}: a free decay grows no mode'
    if residual_rms_m > NOISE_FLOOR_M and not (
        f_std > MIN_RELATIVE_STD * f and zeta_std > MIN_DAMPING_STD
    ):
        return (
            f'{f:.6g} +- {f_std:.2g} Hz, damping ratio {zeta:.3g} +- {zeta_std:.2g} from data '
            f'with {1e6 * residual_rms_m:.3g} um of noise: no uncertainty, an estimator defect'
        )
    return None


def vetted(result: Identification) -> Identification:
    """The identification as it may be published (see the module's text).

    Args:
        result: An identification.

    Returns:
        ``result``, an ERROR when its first mode fails, or without the higher modes that
        fail.
    """
    if result.status == Status.ERROR or not result.modes:
        return result
    noise = result.quality.residual_rms_m
    first = mode_defect(result.modes[0], noise)
    if first is not None:
        return replace(
            result,
            status=Status.ERROR,
            message=f'not published: {first}',
            estimates=Estimates(),
            modes=(),
        )
    kept, notes = [result.modes[0]], []
    for k, mode in enumerate(result.modes[1:], start=2):
        defect = mode_defect(mode, noise)
        if defect is None:
            kept.append(mode)
        else:
            notes.append(f'mode {k} left out: {defect}')
    if not notes:
        return result
    return replace(result, modes=tuple(kept), message='; '.join([result.message, *notes]))
