"""Beam parameters: the dataclasses and their ROS 2 parameter-file form (config/*.yaml)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np
import yaml

from lumpbeam_ros.errors import ConfigError
from lumpbeam_ros.model import rules
from lumpbeam_ros.paramfile import (
    check_known_keys,
    get_choice,
    get_float,
    get_int,
    read_parameter_file,
)
from lumpbeam_ros.resources import config_path

StiffnessSource = Literal['analytic', 'identified']
TipPlacement = Literal['free_end', 'segment_com']

#: doc/interfaces.md, 'Missing effects': each effect's name and its single parameter.
EFFECT_PARAMETERS: dict[str, str] = {
    'base_compliance': 'k_base_nm_per_rad',
    'coulomb_friction': 'torque_nm',
    'quadratic_drag': 'c_q',
    'added_mass': 'mass_kg',
    'sensor_latency': 'latency_s',
    'cubic_stiffness': 'k3_nm_per_rad3',
    'sensor_scale': 'scale',
    'mount_tilt': 'tilt_rad',
}

#: Each effect's parameter when the effect is off (0 for all but ``sensor_scale``: 1).
EFFECT_OFF: dict[str, float] = {name: 0.0 for name in EFFECT_PARAMETERS} | {'sensor_scale': 1.0}

#: Physical limits of each effect's parameter: ``(low, high, low_included)``; the high end is
#: excluded. A negative stiffness, mass, friction, drag or delay, a scale that is not
#: positive, or a clamp tilted to the vertical or beyond describe no real rig.
EFFECT_LIMITS: dict[str, tuple[float, float, bool]] = {
    'base_compliance': (0.0, math.inf, True),
    'coulomb_friction': (0.0, math.inf, True),
    'quadratic_drag': (0.0, math.inf, True),
    'added_mass': (0.0, math.inf, True),
    'sensor_latency': (0.0, math.inf, True),
    'cubic_stiffness': (-math.inf, math.inf, False),
    'sensor_scale': (0.0, math.inf, False),
    'mount_tilt': (-0.5 * math.pi, 0.5 * math.pi, False),
}


def effect_value_problem(name: str, value: float) -> str | None:
    """Why a value is outside an effect's physical limits (:data:`EFFECT_LIMITS`).

    Args:
        name: An effect name of :data:`EFFECT_PARAMETERS`.
        value: Its parameter, SI.

    Returns:
        ``None`` when the value is physical, else what is wrong, e.g. ``'must be positive'``.
    """
    low, high, low_included = EFFECT_LIMITS[name]
    inside = math.isfinite(value) and (value >= low if low_included else value > low)
    if inside and value < high:
        return None
    if low == 0.0 and high == math.inf:
        wanted = 'zero or positive' if low_included else 'positive'
    elif math.isinf(low) and math.isinf(high):
        wanted = 'finite'
    else:
        wanted = f'in ({low:.6g}, {high:.6g})'
    return f'must be {wanted}, got {value!r}'


@dataclass(frozen=True)
class Effects:
    """Physical effects beyond the paper's model (doc/interfaces.md, "Missing effects").

    Every field is 0 when its effect is off; ``sensor_scale`` is therefore stored as its
    excess over 1 (:meth:`value` and :meth:`with_effect` speak the parameter itself).

    Attributes:
        k_base_nm_per_rad: Wall-mount rotational spring in series with joint 1 (0: rigid).
        coulomb_torque_nm: Dry friction torque at joint 1.
        drag_c_q: Quadratic aerodynamic drag on the tip, N s^2/m^2.
        added_mass_kg: Unmodelled point mass at the tip.
        latency_s: Constant delay of the measurement stamps.
        k3_nm_per_rad3: Cubic term of joint 1's spring, torque ``k theta + k3 theta^3``
            (hardening > 0, softening < 0), N m/rad^3.
        scale_excess: ``scale - 1``: the measured tip displacement from rest is ``scale``
            times the true one (a camera with a wrong depth).
        tilt_rad: The clamp's pitch below level: gravity loads the beam at this angle.
    """

    k_base_nm_per_rad: float = 0.0
    coulomb_torque_nm: float = 0.0
    drag_c_q: float = 0.0
    added_mass_kg: float = 0.0
    latency_s: float = 0.0
    k3_nm_per_rad3: float = 0.0
    scale_excess: float = 0.0
    tilt_rad: float = 0.0

    _FIELDS = {
        'base_compliance': 'k_base_nm_per_rad',
        'coulomb_friction': 'coulomb_torque_nm',
        'quadratic_drag': 'drag_c_q',
        'added_mass': 'added_mass_kg',
        'sensor_latency': 'latency_s',
        'cubic_stiffness': 'k3_nm_per_rad3',
        'sensor_scale': 'scale_excess',
        'mount_tilt': 'tilt_rad',
    }

    def with_effect(self, name: str, value: float) -> Effects:
        """Returns a copy with one effect (by its name) set to ``value`` (its SI parameter).

        Raises:
            KeyError: ``name`` is not an effect of :data:`EFFECT_PARAMETERS`.
        """
        return replace(self, **{self._FIELDS[name]: float(value) - EFFECT_OFF[name]})

    def value(self, name: str) -> float:
        """Returns the parameter of one effect (SI), by its name."""
        return float(getattr(self, self._FIELDS[name])) + EFFECT_OFF[name]

    def active(self) -> dict[str, float]:
        """Returns the effects that are switched on, by name."""
        return {
            name: self.value(name)
            for name, attr in self._FIELDS.items()
            if float(getattr(self, attr)) != 0.0
        }

    @property
    def scale(self) -> float:
        """The ``sensor_scale`` parameter (1: a true sensor)."""
        return 1.0 + self.scale_excess

    def physical(self) -> Effects:
        """The effects on the beam itself: the sensor's (latency, scale) switched off."""
        return replace(self, latency_s=0.0, scale_excess=0.0)


@dataclass(frozen=True)
class BeamParameters:
    """The lumped beam of doc/interfaces.md, 'Beam model'.

    Attributes:
        length_m: L.
        bending_stiffness_nm2: EI (used by the analytic rule, B.9).
        mass_kg: m_b, spread evenly over the segments.
        n_segments: n_s.
        stiffness_source: ``'identified'`` (B.13, B.23) or ``'analytic'`` (B.9, c = beta k).
        k_total_nm_per_rad: k_tE (B.12).
        c_total: c_tE (B.22).
        beta_identified: beta of B.23.
        beta_analytic: beta of c = beta k.
        gravity_mps2: g.
        tip_mass_kg: m_d, the mounted body.
        tip_inertia_kgm2: Rotary inertia of the mounted body about its centre.
        tip_placement: ``'free_end'`` (physical) or ``'segment_com'`` (the paper's convention).
        effects: Effects beyond the paper's model.
    """

    length_m: float = 2.3107
    bending_stiffness_nm2: float = 5000.6
    mass_kg: float = 1.90
    n_segments: int = 10
    stiffness_source: StiffnessSource = 'identified'
    k_total_nm_per_rad: float = 3899.1
    c_total: float = 0.08
    beta_identified: float = 12.0
    beta_analytic: float = 2.2e-4
    gravity_mps2: float = 9.81
    tip_mass_kg: float = 2.5
    tip_inertia_kgm2: float = 0.0
    tip_placement: TipPlacement = 'free_end'
    effects: Effects = field(default_factory=Effects)

    @property
    def segment_length_m(self) -> float:
        """L_s = L / n_s."""
        return self.length_m / self.n_segments

    def segment_stiffness(self) -> float:
        """k of joint 1: ``2 EI / L_s`` (B.9) or ``n_s k_tE`` (B.13)."""
        if self.stiffness_source == 'analytic':
            return rules.analytic_segment_stiffness(
                self.bending_stiffness_nm2, self.segment_length_m
            )
        return rules.identified_segment_stiffness(self.k_total_nm_per_rad, self.n_segments)

    def segment_damping(self) -> float:
        """c of joint 1: ``beta k`` (analytic) or ``beta n_s c_tE`` (B.23)."""
        if self.stiffness_source == 'analytic':
            return self.beta_analytic * self.segment_stiffness()
        return rules.identified_segment_damping(
            self.beta_identified, self.c_total, self.n_segments
        )

    def joint_stiffness(self) -> np.ndarray:
        """Stiffness of joints 1..n_s (B.9/B.13 at the clamp, B.10 between segments)."""
        return rules.joint_stiffnesses(self.segment_stiffness(), self.n_segments)

    def joint_damping(self) -> np.ndarray:
        """Damping of joints 1..n_s (B.11, B.23)."""
        return rules.joint_dampings(self.segment_damping(), self.n_segments)

    def with_segments(self, n_segments: int) -> BeamParameters:
        """Returns a copy with another n_s (the rules rescale the joints)."""
        return replace(self, n_segments=n_segments)


@dataclass(frozen=True)
class DropTestConfig:
    """The paper's drop test (section B.3): a load hung at rest, then released.

    Attributes:
        load_kg: m_l.
        release_time_s: When the load is released.
        duration_s: Length of the record.
    """

    load_kg: float = 4.5
    release_time_s: float = 2.0
    duration_s: float = 12.0


_KEYS = frozenset(
    {
        'beam.length_m',
        'beam.bending_stiffness_nm2',
        'beam.mass_kg',
        'beam.n_segments',
        'beam.stiffness_source',
        'beam.k_total_nm_per_rad',
        'beam.c_total',
        'beam.beta_identified',
        'beam.beta_analytic',
        'beam.gravity_mps2',
        'tip.mass_kg',
        'tip.inertia_kgm2',
        'tip.placement',
        'drop_test.load_kg',
        'drop_test.release_time_s',
        'drop_test.duration_s',
    }
    | {f'effects.{name}.{param}' for name, param in EFFECT_PARAMETERS.items()}
)


def beam_from_parameters(params: Mapping[str, Any], source: str | Path) -> BeamParameters:
    """Builds and validates beam parameters from flat (dotted) ROS parameters.

    Missing keys take the defaults of doc/interfaces.md, 'Beam model'.

    Args:
        params: Flat parameters, e.g. from :func:`~lumpbeam_ros.paramfile.read_parameter_file`.
        source: Where they came from, for error messages.

    Returns:
        The beam.

    Raises:
        ConfigError: An unknown key, a wrong type, or a non-positive length, mass, stiffness
            or n_s.
    """
    check_known_keys(params, _KEYS, source)
    d = BeamParameters()
    pos = {'positive': True}
    nonneg = {'non_negative': True}
    effects = Effects()
    for name, param in EFFECT_PARAMETERS.items():
        key = f'effects.{name}.{param}'
        value = get_float(params, key, source, EFFECT_OFF[name])
        problem = effect_value_problem(name, value)
        if problem is not None:
            raise ConfigError(source, key, problem)
        effects = effects.with_effect(name, value)
    return BeamParameters(
        length_m=get_float(params, 'beam.length_m', source, d.length_m, **pos),
        bending_stiffness_nm2=get_float(
            params, 'beam.bending_stiffness_nm2', source, d.bending_stiffness_nm2, **pos
        ),
        mass_kg=get_float(params, 'beam.mass_kg', source, d.mass_kg, **pos),
        n_segments=get_int(params, 'beam.n_segments', source, d.n_segments, minimum=1),
        stiffness_source=get_choice(  # type: ignore[arg-type]
            params, 'beam.stiffness_source', source, ('identified', 'analytic'), 'identified'
        ),
        k_total_nm_per_rad=get_float(
            params, 'beam.k_total_nm_per_rad', source, d.k_total_nm_per_rad, **pos
        ),
        c_total=get_float(params, 'beam.c_total', source, d.c_total, **nonneg),
        beta_identified=get_float(
            params, 'beam.beta_identified', source, d.beta_identified, **nonneg
        ),
        beta_analytic=get_float(params, 'beam.beta_analytic', source, d.beta_analytic, **nonneg),
        gravity_mps2=get_float(params, 'beam.gravity_mps2', source, d.gravity_mps2, **nonneg),
        tip_mass_kg=get_float(params, 'tip.mass_kg', source, d.tip_mass_kg, **nonneg),
        tip_inertia_kgm2=get_float(
            params, 'tip.inertia_kgm2', source, d.tip_inertia_kgm2, **nonneg
        ),
        tip_placement=get_choice(  # type: ignore[arg-type]
            params, 'tip.placement', source, ('free_end', 'segment_com'), 'free_end'
        ),
        effects=effects,
    )


def drop_test_from_parameters(params: Mapping[str, Any], source: str | Path) -> DropTestConfig:
    """Builds the drop-test scenario from flat parameters (defaults of doc/interfaces.md)."""
    d = DropTestConfig()
    return DropTestConfig(
        load_kg=get_float(params, 'drop_test.load_kg', source, d.load_kg, non_negative=True),
        release_time_s=get_float(
            params, 'drop_test.release_time_s', source, d.release_time_s, non_negative=True
        ),
        duration_s=get_float(params, 'drop_test.duration_s', source, d.duration_s, positive=True),
    )


def load_beam_config(path: str | Path | None = None) -> tuple[BeamParameters, DropTestConfig]:
    """Reads a beam parameter file (default: the package's ``config/paper_beam.yaml``).

    Args:
        path: The YAML file, or ``None`` for the default.

    Returns:
        The beam and its drop-test scenario.

    Raises:
        ConfigError: The file is missing or malformed, or a value is invalid.
    """
    path = config_path('paper_beam.yaml') if path is None else Path(path)
    params = read_parameter_file(path)
    return beam_from_parameters(params, path), drop_test_from_parameters(params, path)


def beam_to_parameters(beam: BeamParameters, drop: DropTestConfig | None = None) -> dict[str, Any]:
    """Returns the nested ``ros__parameters`` mapping that reads back as ``beam``."""
    tree: dict[str, Any] = {
        'beam': {
            'length_m': beam.length_m,
            'bending_stiffness_nm2': beam.bending_stiffness_nm2,
            'mass_kg': beam.mass_kg,
            'n_segments': beam.n_segments,
            'stiffness_source': beam.stiffness_source,
            'k_total_nm_per_rad': beam.k_total_nm_per_rad,
            'c_total': beam.c_total,
            'beta_identified': beam.beta_identified,
            'beta_analytic': beam.beta_analytic,
            'gravity_mps2': beam.gravity_mps2,
        },
        'tip': {
            'mass_kg': beam.tip_mass_kg,
            'inertia_kgm2': beam.tip_inertia_kgm2,
            'placement': beam.tip_placement,
        },
        'effects': {
            name: {param: beam.effects.value(name)} for name, param in EFFECT_PARAMETERS.items()
        },
    }
    if drop is not None:
        tree['drop_test'] = {
            'load_kg': drop.load_kg,
            'release_time_s': drop.release_time_s,
            'duration_s': drop.duration_s,
        }
    return tree


def write_beam_config(
    path: str | Path, beam: BeamParameters, drop: DropTestConfig | None = None, header: str = ''
) -> None:
    """Writes a beam parameter file that :func:`load_beam_config` reads back.

    Args:
        path: Output YAML file.
        beam: The beam.
        drop: The drop-test scenario, if any.
        header: Comment lines written first (without ``#``), e.g. where the values came from.
    """
    text = ''.join(f'# {line}\n' for line in header.splitlines())
    text += yaml.safe_dump(
        {'/**': {'ros__parameters': beam_to_parameters(beam, drop)}}, sort_keys=False
    )
    Path(path).write_text(text, encoding='utf-8')
