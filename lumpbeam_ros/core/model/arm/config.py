"""The flexible arm's configuration file (doc/arm.md): links, joints, plane and payload.

The file is plain YAML with one top-level ``arm`` mapping::

    arm:
      plane: vertical          # or horizontal (gravity out of the plane, not modelled)
      payload_kg: 0.5          # point mass at the free end of the last link
      links:                   # from joint 1 outward
        - length_m: 1.2
          n_segments: 10
          ei_nm2: 5000.6       # or a list of n_segments values; or k_total_nm_per_rad
          mass_kg: 1.9         # or a list of n_segments segment masses
          damping_beta: 2.2e-4
          joint_mass_kg: 0.0
          joint_limits_rad: [-3.1, 3.1]   # optional: the range of the link's joint

:func:`write_arm_config` writes an arm back (the identified arm, ``--write-arm``).

Every bad value is a :class:`~lumpbeam_ros.base.errors.ConfigError` naming the file and the key
(``arm.links[1].ei_nm2``), printed by the command line as one line.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np
import yaml

from lumpbeam_ros.base.errors import ConfigError, LumpbeamError
from lumpbeam_ros.base.paramfile import (
    check_known_keys,
    get_choice,
    get_float,
    get_int,
    read_yaml_document,
)
from lumpbeam_ros.core.model import rules

Plane = Literal['vertical', 'horizontal']

#: g in a vertical arm, m/s^2 (the beam's value).
GRAVITY_MPS2 = 9.81

_ARM_KEYS = frozenset({'plane', 'payload_kg', 'links'})
_LINK_KEYS = frozenset(
    {
        'length_m',
        'n_segments',
        'ei_nm2',
        'k_total_nm_per_rad',
        'mass_kg',
        'damping_beta',
        'joint_mass_kg',
        'joint_limits_rad',
    }
)


@dataclass(frozen=True)
class LinkConfig:
    """One flexible link: a lumped chain of rigid segments.

    Attributes:
        length_m: The link's length, m.
        n_segments: n_s.
        segment_masses_kg: Mass of each segment, kg (at its centre, inertia ``m L_s^2/12``).
        damping_beta: ``c / k`` of every spring, s.
        joint_mass_kg: Point mass at the link's start (the motor driving it), kg.
        ei_nm2: EI of each segment, N m^2, or ``None`` when the link is given by
            ``k_total_nm_per_rad``.
        k_total_nm_per_rad: The identified total stiffness k_tE (B.12), or ``None``.
        joint_limits_rad: The range ``(low, high)`` of the link's joint, rad, or ``None``.
    """

    length_m: float
    n_segments: int
    segment_masses_kg: tuple[float, ...]
    damping_beta: float = 0.0
    joint_mass_kg: float = 0.0
    ei_nm2: tuple[float, ...] | None = None
    k_total_nm_per_rad: float | None = None
    joint_limits_rad: tuple[float, float] | None = None

    @property
    def segment_length_m(self) -> float:
        """L_s = length / n_s."""
        return self.length_m / self.n_segments

    @property
    def mass_kg(self) -> float:
        """The link's total mass, kg."""
        return float(sum(self.segment_masses_kg))

    def spring_stiffness(self) -> np.ndarray:
        """Stiffness of the link's springs, clamp first, N m/rad.

        From EI: ``2 EI_1 / L_s`` at the clamp (B.9) and the series pair
        ``1 / (L_s / (2 EI_{j-1}) + L_s / (2 EI_j))`` between segments (B.10 for unequal
        halves). From k_tE: ``n_s k_tE`` at the clamp, half of it between segments (B.13,
        B.10).
        """
        ls = self.segment_length_m
        if self.ei_nm2 is None:
            assert self.k_total_nm_per_rad is not None
            k = rules.identified_segment_stiffness(self.k_total_nm_per_rad, self.n_segments)
            return rules.joint_stiffnesses(k, self.n_segments)
        half = np.array([rules.analytic_segment_stiffness(ei, ls) for ei in self.ei_nm2])
        stiffness = np.empty(self.n_segments)
        stiffness[0] = half[0]
        stiffness[1:] = 1.0 / (1.0 / half[:-1] + 1.0 / half[1:])
        return stiffness

    def spring_damping(self) -> np.ndarray:
        """Damping of the link's springs, ``c = beta k`` spring by spring, N m s/rad."""
        return self.damping_beta * self.spring_stiffness()


@dataclass(frozen=True)
class ArmConfig:
    """A planar arm of flexible links driven by ideal stiff servos.

    Attributes:
        links: The links from joint 1 outward.
        plane: ``'vertical'`` (gravity -z in the plane) or ``'horizontal'`` (none in it).
        payload_kg: Point mass at the free end of the last link, kg.
        source: The file it was read from, for messages.
    """

    links: tuple[LinkConfig, ...]
    plane: Plane = 'vertical'
    payload_kg: float = 0.0
    source: str = ''

    @property
    def n_joints(self) -> int:
        """One joint per link."""
        return len(self.links)

    @property
    def gravity_mps2(self) -> float:
        """g in the arm's plane: 9.81 vertical, 0 horizontal."""
        return GRAVITY_MPS2 if self.plane == 'vertical' else 0.0

    def with_payload(self, payload_kg: float) -> ArmConfig:
        """A copy with another payload."""
        return replace(self, payload_kg=float(payload_kg))

    def check_within_limits(self, q: np.ndarray, what: str) -> None:
        """Refuses joint angles outside a link's ``joint_limits_rad``.

        Args:
            q: Angles, rad, (n_joints,) or (samples, n_joints).
            what: What the angles are, for the message (``'IN.csv'``).

        Raises:
            LumpbeamError: An angle outside its joint's range, naming the joint and the first
                angle found outside.
        """
        angles = np.atleast_2d(np.asarray(q, dtype=float))
        for j, link in enumerate(self.links):
            if link.joint_limits_rad is None or j >= angles.shape[1]:
                continue
            low, high = link.joint_limits_rad
            outside = np.flatnonzero((angles[:, j] < low) | (angles[:, j] > high))
            if outside.size:
                value = angles[outside[0], j]
                raise LumpbeamError(
                    f'{what}: joint_{j + 1} at {value:.6g} rad is outside its limits '
                    f'[{low:.6g}, {high:.6g}] rad ({self.source or "the arm file"})'
                )


def _per_segment(
    value: Any, key: str, source: str | Path, n_segments: int, *, positive: bool
) -> tuple[float, ...]:
    """A number spread over the segments (``spread``) or a list of one value per segment."""
    if isinstance(value, Sequence) and not isinstance(value, str):
        if len(value) != n_segments:
            raise ConfigError(
                source, key, f'needs {n_segments} values (one per segment), got {len(value)}'
            )
        flat = {f'{key}[{i}]': v for i, v in enumerate(value)}
        return tuple(get_float(flat, k, source, positive=positive) for k in flat)
    return (get_float({key: value}, key, source, positive=positive),)


def _link(raw: Any, prefix: str, source: str | Path) -> LinkConfig:
    """One entry of ``arm.links``."""
    if not isinstance(raw, Mapping):
        raise ConfigError(source, prefix, 'expected a mapping of link keys')
    params = {f'{prefix}.{k}': v for k, v in raw.items()}
    check_known_keys(params, {f'{prefix}.{k}' for k in _LINK_KEYS}, source)
    length = get_float(params, f'{prefix}.length_m', source, positive=True)
    n = get_int(params, f'{prefix}.n_segments', source, minimum=1)
    has_ei = f'{prefix}.ei_nm2' in params
    has_k = f'{prefix}.k_total_nm_per_rad' in params
    if has_ei == has_k:
        raise ConfigError(
            source,
            f'{prefix}.ei_nm2',
            'give exactly one of ei_nm2 and k_total_nm_per_rad'
            if has_ei
            else 'missing (or give k_total_nm_per_rad)',
        )
    ei = k_total = None
    if has_ei:
        key = f'{prefix}.ei_nm2'
        ei = _per_segment(params[key], key, source, n, positive=True)
        ei = ei * n if len(ei) == 1 else ei
    else:
        k_total = get_float(params, f'{prefix}.k_total_nm_per_rad', source, positive=True)
    key = f'{prefix}.mass_kg'
    if key not in params:
        raise ConfigError(source, key, 'missing')
    masses = _per_segment(params[key], key, source, n, positive=True)
    masses = (masses[0] / n,) * n if len(masses) == 1 and n > 1 else masses
    return LinkConfig(
        length_m=length,
        n_segments=n,
        segment_masses_kg=masses,
        damping_beta=get_float(params, f'{prefix}.damping_beta', source, 0.0, non_negative=True),
        joint_mass_kg=get_float(params, f'{prefix}.joint_mass_kg', source, 0.0, non_negative=True),
        ei_nm2=ei,
        k_total_nm_per_rad=k_total,
        joint_limits_rad=_limits(params, f'{prefix}.joint_limits_rad', source),
    )


def _limits(params: Mapping[str, Any], key: str, source: str | Path) -> tuple[float, float] | None:
    """A link's optional ``joint_limits_rad: [LOW, HIGH]``."""
    if key not in params:
        return None
    value = params[key]
    if not isinstance(value, Sequence) or isinstance(value, str) or len(value) != 2:
        raise ConfigError(source, key, f'expected [LOW, HIGH] in rad, got {value!r}')
    low = get_float({key: value[0]}, key, source)
    high = get_float({key: value[1]}, key, source)
    if not low < high:
        raise ConfigError(source, key, f'LOW {low!r} must be below HIGH {high!r}')
    return low, high


def arm_from_mapping(document: Any, source: str | Path) -> ArmConfig:
    """Builds and validates an arm from a parsed YAML document.

    Args:
        document: The document (a mapping with the key ``arm``).
        source: Where it came from, for messages.

    Returns:
        The arm.

    Raises:
        ConfigError: A missing, unknown, non-finite or out-of-range value, a list of the
            wrong length, an unknown plane.
    """
    if not isinstance(document, Mapping) or not isinstance(document.get('arm'), Mapping):
        raise ConfigError(source, 'arm', 'missing: expected a mapping under the key arm')
    check_known_keys(dict.fromkeys(map(str, document)), {'arm'}, source)
    raw = document['arm']
    params = {f'arm.{k}': v for k, v in raw.items()}
    check_known_keys(params, {f'arm.{k}' for k in _ARM_KEYS}, source)
    links = params.get('arm.links')
    if not isinstance(links, list) or not links:
        raise ConfigError(source, 'arm.links', 'expected a non-empty list of links')
    plane = get_choice(params, 'arm.plane', source, ('vertical', 'horizontal'), 'vertical')
    return ArmConfig(
        links=tuple(_link(link, f'arm.links[{i}]', source) for i, link in enumerate(links)),
        plane='vertical' if plane == 'vertical' else 'horizontal',
        payload_kg=get_float(params, 'arm.payload_kg', source, 0.0, non_negative=True),
        source=str(source),
    )


def _uniform(values: tuple[float, ...]) -> bool:
    return all(v == values[0] for v in values)


def link_to_mapping(link: LinkConfig) -> dict[str, Any]:
    """One entry of ``arm.links`` that :func:`arm_from_mapping` reads back as ``link``."""
    entry: dict[str, Any] = {'length_m': link.length_m, 'n_segments': link.n_segments}
    if link.ei_nm2 is not None:
        ei = link.ei_nm2
        entry['ei_nm2'] = ei[0] if _uniform(ei) else list(ei)
    else:
        entry['k_total_nm_per_rad'] = link.k_total_nm_per_rad
    masses = link.segment_masses_kg
    entry['mass_kg'] = link.mass_kg if _uniform(masses) else list(masses)
    entry['damping_beta'] = link.damping_beta
    entry['joint_mass_kg'] = link.joint_mass_kg
    if link.joint_limits_rad is not None:
        entry['joint_limits_rad'] = list(link.joint_limits_rad)
    return entry


def arm_to_mapping(arm: ArmConfig) -> dict[str, Any]:
    """The document of an arm file that :func:`arm_from_mapping` reads back as ``arm``."""
    return {
        'arm': {
            'plane': arm.plane,
            'payload_kg': arm.payload_kg,
            'links': [link_to_mapping(link) for link in arm.links],
        }
    }


def write_arm_config(path: str | Path, arm: ArmConfig, header: str = '') -> None:
    """Writes an arm file that :func:`load_arm_config` reads back.

    A uniform link's mass is written as its total (its segments' masses may then differ from
    the read-back ones in the last bit).

    Args:
        path: Output YAML file.
        arm: The arm.
        header: Comment lines written first (without ``#``), e.g. where the values came from.

    Raises:
        LumpbeamError: The file cannot be written.
    """
    text = ''.join(f'# {line}\n' for line in header.splitlines())
    text += yaml.safe_dump(arm_to_mapping(arm), sort_keys=False)
    try:
        Path(path).write_text(text, encoding='utf-8')
    except OSError as exc:
        raise LumpbeamError(f'{path}: cannot write the arm file: {exc.strerror}') from None


def load_arm_config(path: str | Path) -> ArmConfig:
    """Reads an arm configuration file.

    Args:
        path: The YAML file.

    Returns:
        The arm.

    Raises:
        ConfigError: The file is missing, unreadable, not YAML, or holds a bad value.
    """
    return arm_from_mapping(read_yaml_document(path), path)
