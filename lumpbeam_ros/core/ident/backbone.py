"""The beam's backbone: how much faster its first mode runs at a larger amplitude.

A lumped chain (B.1-B.8) is geometrically nonlinear: at a tip amplitude ``A`` its first mode
runs at ``omega(A) = omega_0 (1 + gamma A^2 + O(A^4))``, the backbone curve of a weakly
nonlinear oscillator (Nayfeh and Mook, *Nonlinear Oscillations*, 1979, section 4.1). A free
decay's least-squares fit can hardly tell this shift from the frequency itself (the shift
decays with the squared envelope, nearly a ramp of the phase over a record), so its own
estimate costs the frequency most of its precision; the model knows it instead.

``gamma`` is measured on the model itself: the undamped chain of the configured geometry,
without effects, released from its static deflection under a tip load (a tip amplitude of
:data:`AMPLITUDE_OF_LENGTH` of the length) over :data:`PERIODS` periods; a damped sinusoid
fitted to the tip z gives ``omega`` and ``A``, and ``gamma = (omega - omega_0) / (omega_0
A^2)`` with ``omega_0`` the chain's linear first mode (B.16 linearised). ``gamma`` scales the
frequency, so it hardly depends on the stiffness (within 0.3 % over a stiffness range of 2.4
for the paper's beam): a beam whose stiffness is not yet known gives it too.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.sinusoid import DampedSinusoidFit
from lumpbeam_ros.core.model.adopt import first_mode
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig, Effects
from lumpbeam_ros.core.model.simulate import simulate_drop_test
from lumpbeam_ros.core.model.statics import static_tip_deflection

#: The release amplitude, as a fraction of the beam's length: large enough that the shift
#: (some ppm) stands far above what the second mode and the fit leave, small enough that the
#: ``A^4`` term is negligible (under 1 % of ``gamma`` at twice this).
AMPLITUDE_OF_LENGTH = 0.02
#: Periods of the first mode simulated per amplitude.
PERIODS = 16
#: Samples per period of the first mode.
SAMPLES_PER_PERIOD = 40
#: The simulator's steps per sample: with two, ``gamma`` is within 0.1 % of MuJoCo's for the
#: paper's beam (one step per sample leaves it lower; a grid off the samples, some % off).
STEPS_PER_SAMPLE = 2


@dataclass(frozen=True)
class Backbone:
    """The first mode's frequency against its tip amplitude, ``omega_0 (1 + gamma A^2)``.

    Attributes:
        relative_per_m2: ``gamma``, 1/m^2 (of the tip's vertical amplitude).
        natural_frequency_hz: ``omega_0 / 2 pi`` of the undamped chain, Hz.
    """

    relative_per_m2: float
    natural_frequency_hz: float


@functools.lru_cache(maxsize=8)
def beam_backbone(beam: BeamParameters) -> Backbone:
    """The backbone of ``beam``'s chain (see the module docstring).

    Cached per beam: it costs a short simulation (about 15 ms).

    Args:
        beam: The beam; its damping and effects are left out.

    Returns:
        Its backbone.

    Raises:
        LumpbeamError: The chain has no oscillating mode or bends the wrong way under a tip
            load, or a simulation or fit fails.
    """
    chain = replace(beam, c_total=0.0, beta_identified=0.0, beta_analytic=0.0, effects=Effects())
    f0 = first_mode(chain)[0]
    per_kg = static_tip_deflection(chain, 1.0) - static_tip_deflection(chain, 0.0)
    if not (per_kg > 0.0 and math.isfinite(per_kg) and f0 > 0.0):
        raise LumpbeamError('backbone: the beam does not sag under a tip load')
    rate = SAMPLES_PER_PERIOD * f0
    load = AMPLITUDE_OF_LENGTH * beam.length_m / per_kg
    drop = DropTestConfig(load, 0.0, PERIODS / f0)
    tip = simulate_drop_test(chain, drop, rate, 1.0 / (STEPS_PER_SAMPLE * rate))
    mode = DampedSinusoidFit(n_modes=1).fit(tip.t, tip.z).mode(0)
    gamma = (mode.natural_frequency_hz - f0) / (f0 * mode.amplitude**2)
    if not math.isfinite(gamma):
        raise LumpbeamError('backbone: the fitted frequency is not finite')
    return Backbone(float(gamma), float(f0))
