"""Beam parameters: the dataclasses and their ROS 2 parameter-file form (config/*.yaml)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Any, Literal, get_args

import numpy as np
import yaml

from lumpbeam_ros.base.paramfile import check_known_keys, parameter_file
from lumpbeam_ros.base.schema import (
    Bounds,
    ParameterSpec,
    setting,
    settings_from_parameters,
    settings_specs,
    settings_to_parameters,
)
from lumpbeam_ros.core.model import rules

StiffnessSource = Literal['analytic', 'identified']
TipPlacement = Literal['free_end', 'segment_com']

#: Where an effect enters the dynamics: the chain's masses, springs and forces
#: (:meth:`~lumpbeam_ros.core.model.chain.LumpedChain.from_beam`), the stamps of the measurements
#: (:func:`~lumpbeam_ros.core.model.simulate.simulate_loads`, the stream) or the measured position
#: (:func:`~lumpbeam_ros.core.model.sensor.measured_position`).
EffectHook = Literal['chain', 'stamps', 'position']

_POSITIVE = Bounds(0.0, low_open=True)
_NON_NEGATIVE = Bounds(0.0)


@dataclass(frozen=True)
class SearchRange:
    """The search of an effect's strength (:mod:`lumpbeam_ros.core.diagnose.candidates`).

    Each number is a multiple of the reference named at its place in :attr:`per` (``''``:
    SI as it stands; ``'clamp_moment'``: the clamp's static moment of the carried masses, N m;
    ``'carried_kg'``: the tip's and the beam's masses; ``'k3_unit'``: the cubic term that adds
    1 % to the clamp's tangent stiffness at its rest angle).

    Attributes:
        scale: Unit of the fitted strength.
        search_max: Largest strength searched.
        plausible_max: Largest strength a real setup can have.
        start: Strength a fit starts from: small, but felt by the data.
        per: The reference of each of the four.
    """

    scale: float
    search_max: float
    plausible_max: float
    start: float
    per: tuple[str, str, str, str] = ('', '', '', '')


@dataclass(frozen=True)
class EffectRecord:
    """One physical effect beyond the paper's model (doc/interfaces.md, "Missing effects").

    Attributes:
        name: The contract name (``base_compliance``).
        parameter: Its one parameter's contract name (``k_base_nm_per_rad``).
        unit: The parameter's unit (empty: none).
        meaning: What the parameter is, one line.
        limits: The values the model simulates: physical, and no stiffer, heavier or slower
            than the integrator handles (a test runs the model at each end).
        off: The parameter's value that switches the effect off.
        hook: Where it enters the dynamics (:data:`EffectHook`).
        search: How the diagnosis searches it.
        signed: Its strength has a sign (searched on both sides of off).
        compliance: The diagnosis fits ``k_clamp / value`` (0: off) instead of the value, for
            an effect whose off value would be an infinite stiffness.
        signature: The panel of the diagnosis's signature figure that speaks for it
            (``'time_shift'``, ``'frequency'``, ``'envelope'``; empty: none).
    """

    name: str
    parameter: str
    unit: str
    meaning: str
    limits: Bounds
    off: float
    hook: EffectHook
    search: SearchRange
    signed: bool = False
    compliance: bool = False
    signature: str = ''

    @property
    def key(self) -> str:
        """Its parameter's dotted name in a beam file: ``effects.<name>.<parameter>``."""
        return f'effects.{self.name}.{self.parameter}'

    def problem(self, value: float) -> str | None:
        """Why ``value`` is outside :attr:`limits` (``None``: inside).

        Returns:
            ``None``, or e.g. ``'must be in [0, 1], got 1.5'``.
        """
        if math.isfinite(value) and self.limits.contains(value):
            return None
        return f'must be {self.limits.describe()}, got {value!r}'


def _effect(record: EffectRecord) -> Any:
    """The :class:`Effects` field of an effect: off by default, its record attached.

    The field is also the effect's parameter in a beam file (:func:`beam_from_parameters`).
    """
    spec = ParameterSpec(
        record.key, 'double', record.off, record.meaning, record.unit, record.limits
    )
    return field(default=record.off, metadata={'effect': record, 'parameter': spec})


@dataclass(frozen=True)
class Effects:
    """Physical effects beyond the paper's model, one field and record each.

    A field is the effect's contract parameter, SI, and equals the record's ``off`` when the
    effect is off (0 for all but ``sensor_scale``: 1). Adding an effect is one field here
    plus its physics at its hook.
    """

    k_base_nm_per_rad: float = _effect(
        EffectRecord(
            'base_compliance',
            'k_base_nm_per_rad',
            'N m/rad',
            'the wall mount is a rotational spring in series with joint 1 (0: rigid)',
            # A mount a million times stiffer than any joint of a lab beam is rigid.
            Bounds(0.0, 1e10),
            0.0,
            'chain',
            # Compliance relative to the clamp joint; a mount 20 times softer than the beam's
            # own root (k_base < k_clamp / 20) is not "a beam on a mount".
            SearchRange(1.0, 1000.0, 20.0, 0.1),
            compliance=True,
            signature='frequency',
        )
    )
    coulomb_torque_nm: float = _effect(
        EffectRecord(
            'coulomb_friction',
            'torque_nm',
            'N m',
            'dry friction torque at joint 1',
            Bounds(0.0, 1000.0),
            0.0,
            'chain',
            # Dry friction beyond a tenth of the clamp's static moment would lock the beam.
            SearchRange(1.0, 1.0, 0.1, 0.1, ('', 'clamp_moment', 'clamp_moment', '')),
            signature='envelope',
        )
    )
    drag_c_q: float = _effect(
        EffectRecord(
            'quadratic_drag',
            'c_q',
            'N s^2/m^2',
            'aerodynamic force -c_q abs(v) v on the tip',
            Bounds(0.0, 20.0),
            0.0,
            'chain',
            # c_q = rho C_d A / 2: 20 N s^2/m^2 is a plate of ~30 m^2; a tip body is far less.
            SearchRange(1.0, 1e3, 20.0, 0.05),
            signature='envelope',
        )
    )
    added_mass_kg: float = _effect(
        EffectRecord(
            'added_mass',
            'mass_kg',
            'kg',
            'an unmodelled point mass at the tip (a camera, a bracket)',
            Bounds(0.0, 100.0),
            0.0,
            'chain',
            # More than twice what the beam already carries is not an unnoticed bracket.
            SearchRange(1.0, 20.0, 2.0, 0.03, ('', 'carried_kg', 'carried_kg', '')),
            signature='frequency',
        )
    )
    latency_s: float = _effect(
        EffectRecord(
            'sensor_latency',
            'latency_s',
            's',
            'measurement stamps are late by a constant delay',
            Bounds(0.0, 1.0),
            0.0,
            'stamps',
            # Beyond a quarter of a second a camera pipeline is broken, not late.
            SearchRange(0.01, 2.0, 0.25, 0.002),
            signature='time_shift',
        )
    )
    k3_nm_per_rad3: float = _effect(
        EffectRecord(
            'cubic_stiffness',
            'k3_nm_per_rad3',
            'N m/rad^3',
            "joint 1's torque is k theta + k3 theta^3 (hardening > 0, softening < 0)",
            # Softening: the spring's torque peaks at (2/3) k theta* with theta* = sqrt(k / 3|k3|),
            # so a clamp (k ~ 3.9e4 N m/rad on the paper's beam) carrying a static moment M
            # snaps through beyond |k3| = 4 k^3 / (27 M^2), 2.7e8 with the paper's load (the
            # integration then runs away). Hardening: beyond 1e9 the swing of a release
            # (0.02 rad) multiplies the tangent stiffness thirty-fold and the integration
            # stalls on its steps.
            Bounds(-1e8, 1e9),
            0.0,
            'chain',
            # Half the clamp's stiffness gained or lost over the swing is not a mild
            # nonlinearity.
            SearchRange(1.0, 500.0, 50.0, 1.0, ('k3_unit',) * 4),
            signed=True,
            signature='frequency',
        )
    )
    scale: float = _effect(
        EffectRecord(
            'sensor_scale',
            'scale',
            '',
            'the measured displacement from rest is scale times the true one (1: true)',
            Bounds(0.0, 10.0, low_open=True),
            1.0,
            'position',
            # A camera 30 % off in depth is a wrong calibration, not a small scale error.
            SearchRange(0.01, 0.9, 0.3, 0.002),
            signed=True,
        )
    )
    tilt_rad: float = _effect(
        EffectRecord(
            'mount_tilt',
            'tilt_rad',
            'rad',
            'the clamp is pitched this far below level: gravity loads the beam at phi + tilt',
            # Short of vertical: a clamp at +-90 degrees is a hanging or standing beam.
            Bounds(-1.5, 1.5),
            0.0,
            'chain',
            # A clamp tilted more than 10 degrees is a different setup, not an unnoticed tilt.
            SearchRange(0.01, 1.2, 0.175, 0.002),
            signed=True,
        )
    )

    creep_rate_mps: float = _effect(
        EffectRecord(
            'mount_creep',
            'rate_mps',
            'm/s',
            'the clamp creeps vertically at a constant rate (a mount settling, thermal drift): '
            'the measured tip z moves by rate times the time since the record began',
            # A centimetre a second is a clamp coming loose, not a creep.
            Bounds(-0.01, 0.01),
            0.0,
            'position',
            # A millimetre a second (6 cm a minute) is beyond any creep that goes unnoticed.
            SearchRange(1e-4, 0.01, 1e-3, 1e-5),
            signed=True,
        )
    )

    @classmethod
    def records(cls) -> tuple[EffectRecord, ...]:
        """Every effect's record, in the order of doc/interfaces.md, "Missing effects"."""
        return tuple(f.metadata['effect'] for f in fields(cls))

    def with_effect(self, name: str, value: float) -> Effects:
        """Returns a copy with one effect (by its name) set to ``value`` (its SI parameter).

        Raises:
            KeyError: ``name`` is not an effect of :data:`EFFECT_PARAMETERS`.
        """
        return replace(self, **{_FIELD[name]: float(value)})

    def value(self, name: str) -> float:
        """Returns the parameter of one effect (SI), by its name."""
        return float(getattr(self, _FIELD[name]))

    def active(self) -> dict[str, float]:
        """Returns the effects that are switched on, by name."""
        return {r.name: self.value(r.name) for r in self.records() if self.value(r.name) != r.off}

    def physical(self) -> Effects:
        """The effects on the beam itself: the sensor's (at the stamps, the position) off."""
        sensor = {_FIELD[r.name]: r.off for r in self.records() if r.hook != 'chain'}
        return replace(self, **sensor)


#: Every effect's record, by name.
EFFECTS: dict[str, EffectRecord] = {r.name: r for r in Effects.records()}
_FIELD: dict[str, str] = {f.metadata['effect'].name: f.name for f in fields(Effects)}

#: Each effect's name and its single parameter.
EFFECT_PARAMETERS: dict[str, str] = {name: r.parameter for name, r in EFFECTS.items()}

#: Each effect's parameter when the effect is off.
EFFECT_OFF: dict[str, float] = {name: r.off for name, r in EFFECTS.items()}


def effect_value_problem(name: str, value: float) -> str | None:
    """Why a value is outside an effect's limits (:attr:`EffectRecord.limits`).

    Args:
        name: An effect name of :data:`EFFECTS`.
        value: Its parameter, SI.

    Returns:
        ``None`` when the model simulates it, else what is wrong, e.g.
        ``'must be in [0, 1], got 1.5'``.
    """
    return EFFECTS[name].problem(value)


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

    length_m: float = setting('beam.length_m', 2.3107, 'L', 'm', _POSITIVE)
    bending_stiffness_nm2: float = setting(
        'beam.bending_stiffness_nm2', 5000.6, 'EI (the analytic rule, B.9)', 'N m^2', _POSITIVE
    )
    mass_kg: float = setting('beam.mass_kg', 1.90, 'm_b', 'kg', _POSITIVE)
    n_segments: int = setting('beam.n_segments', 10, 'n_s', bounds=Bounds(1.0))
    stiffness_source: StiffnessSource = setting(
        'beam.stiffness_source',
        'identified',
        'joint 1 from k_tE (B.13, B.23) or from EI (B.9)',
        choices=get_args(StiffnessSource),
    )
    k_total_nm_per_rad: float = setting(
        'beam.k_total_nm_per_rad', 3899.1, 'k_tE (B.12)', 'N m/rad', _POSITIVE
    )
    c_total: float = setting('beam.c_total', 0.08, 'c_tE (B.22)', '1/s', _NON_NEGATIVE)
    beta_identified: float = setting(
        'beam.beta_identified', 12.0, 'beta of B.23', '', _NON_NEGATIVE
    )
    beta_analytic: float = setting(
        'beam.beta_analytic', 2.2e-4, 'beta of c = beta k', 's', _NON_NEGATIVE
    )
    gravity_mps2: float = setting('beam.gravity_mps2', 9.81, 'g', 'm/s^2', _NON_NEGATIVE)
    tip_mass_kg: float = setting('tip.mass_kg', 2.5, 'm_d', 'kg', _NON_NEGATIVE)
    tip_inertia_kgm2: float = setting(
        'tip.inertia_kgm2', 0.0, 'rotary inertia of the mounted body', 'kg m^2', _NON_NEGATIVE
    )
    tip_placement: TipPlacement = setting(
        'tip.placement',
        'free_end',
        'where the tip masses sit on the last segment',
        choices=get_args(TipPlacement),
    )
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

    load_kg: float = setting('drop_test.load_kg', 4.5, 'm_l', 'kg', _NON_NEGATIVE)
    release_time_s: float = setting(
        'drop_test.release_time_s', 2.0, 'when the load is released', 's', _NON_NEGATIVE
    )
    duration_s: float = setting('drop_test.duration_s', 12.0, 'record length', 's', _POSITIVE)


#: Every key of a beam file.
_KEYS = frozenset(
    spec.name for cls in (BeamParameters, Effects, DropTestConfig) for spec in settings_specs(cls)
)


def beam_from_parameters(params: Mapping[str, Any], source: str | Path) -> BeamParameters:
    """Builds and validates beam parameters from flat (dotted) ROS parameters.

    Missing keys take the defaults of doc/interfaces.md, 'Beam model'; the keys, defaults and
    bounds are the fields' of :class:`BeamParameters` and :class:`Effects`.

    Args:
        params: Flat parameters, e.g. from
            :func:`~lumpbeam_ros.base.paramfile.read_parameter_file`.
        source: Where they came from, for error messages.

    Returns:
        The beam.

    Raises:
        ConfigError: An unknown key, a wrong type, or a value out of its bounds.
    """
    check_known_keys(params, _KEYS, source)
    beam = settings_from_parameters(BeamParameters, params, source)
    return replace(beam, effects=settings_from_parameters(Effects, params, source))


def drop_test_from_parameters(params: Mapping[str, Any], source: str | Path) -> DropTestConfig:
    """Builds the drop-test scenario from flat parameters (defaults of doc/interfaces.md)."""
    return settings_from_parameters(DropTestConfig, params, source)


def load_beam_config(path: str | Path | None = None) -> tuple[BeamParameters, DropTestConfig]:
    """Reads a beam parameter file (default: the package's ``config/paper_beam.yaml``).

    Args:
        path: The YAML file, or ``None`` for the default.

    Returns:
        The beam and its drop-test scenario.

    Raises:
        ConfigError: The file is missing or malformed, or a value is invalid.
    """
    source, params = parameter_file(path, 'paper_beam.yaml')
    return beam_from_parameters(params, source), drop_test_from_parameters(params, source)


def beam_to_parameters(beam: BeamParameters, drop: DropTestConfig | None = None) -> dict[str, Any]:
    """Returns the nested ``ros__parameters`` mapping that reads back as ``beam``."""
    flat = {**settings_to_parameters(beam), **settings_to_parameters(beam.effects)}
    if drop is not None:
        flat.update(settings_to_parameters(drop))
    tree: dict[str, Any] = {}
    for key, value in flat.items():
        *sections, name = key.split('.')
        node = tree
        for section in sections:
            node = node.setdefault(section, {})
        node[name] = value
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
