"""The arm learned live: its links, or its payload, fitted again after every ring-down.

The identifier node, given an arm file, hands each identification of the current ring-down
to an :class:`ArmLearner`. Once a ring-down (the joints at rest after a move) has lasted
``ring_down_s``, its modes and the joints' angles become one more
:class:`~lumpbeam_ros.core.ident.arm.link_fit.ModeObservation`, and the links are fitted
again from every ring-down seen so far
(:class:`~lumpbeam_ros.core.ident.arm.link_fit.LinkParameterFit`, the arm file's values the
start), or the payload (:class:`~lumpbeam_ros.core.ident.arm.payload_fit.PayloadFit`).

The result travels as one DiagnosticStatus ``lumpbeam/arm`` on ``/arm_params``: level OK
once every unknown is determined, WARN while the ring-downs seen do not determine them; its
KeyValues are :meth:`ArmEstimate.key_values`, read back by :func:`arm_from_status` (the
shaper node and the simulator node take the identified arm from them).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.arm.link_fit import (
    MAX_FACTOR,
    LinkEstimate,
    LinkParameterFit,
    MeasuredMode,
    ModeObservation,
    link_stiffness_total,
    scaled_arm,
)
from lumpbeam_ros.core.ident.arm.payload_fit import MAX_PAYLOAD, PayloadFit, moving_mass_kg
from lumpbeam_ros.core.ident.identification import Identification, Status
from lumpbeam_ros.core.ident.ring_down import JointRest
from lumpbeam_ros.core.model.arm.config import ArmConfig

#: The KeyValue with the number of ring-downs fitted.
RING_DOWNS_KEY = 'ring_downs'
#: Ring-downs kept (the oldest are forgotten past it).
MAX_RING_DOWNS = 50
#: The largest ``damping_beta`` taken from ``/arm_params``, s: a spring's damper ``c = beta k``
#: with beta a second damps every mode above 0.3 Hz past critical.
MAX_BETA_S = 1.0


def link_key(i: int, name: str) -> str:
    """The KeyValue of link ``i``'s (1-based) ``name``, e.g. ``link_2_damping_beta``."""
    return f'link_{i}_{name}'


@dataclass(frozen=True)
class ArmEstimate:
    """What ``/arm_params`` carries after a fit.

    Attributes:
        status: OK once every unknown is determined, else WARN.
        message: Why, in one line.
        ring_downs: Ring-downs fitted.
        links: The fitted links (empty when fitting the payload or when undetermined).
        payload: The fitted payload and its std, kg (when fitting the payload and determined).
        arm: The arm with the fitted values (``None`` while undetermined).
    """

    status: Status
    message: str
    ring_downs: int
    links: tuple[LinkEstimate, ...] = ()
    payload: tuple[float, float] | None = None
    arm: ArmConfig | None = None

    def key_values(self) -> list[tuple[str, str]]:
        """The status's KeyValues, in order: the links' or the payload's, then the count."""
        pairs: list[tuple[str, str]] = []
        for i, link in enumerate(self.links, start=1):
            pairs += [(link_key(i, name), repr(value)) for name, value in link.as_dict().items()]
        if self.payload is not None:
            pairs += [
                ('payload_kg', repr(self.payload[0])),
                ('payload_kg_std', repr(self.payload[1])),
            ]
        pairs.append((RING_DOWNS_KEY, str(self.ring_downs)))
        return pairs


def observation_of(rest: JointRest, result: Identification) -> ModeObservation | None:
    """The ring-down's modes at the joints' rest, or ``None`` when none has a usable std."""
    modes = []
    for mode in result.modes:
        measured = MeasuredMode.of(mode)
        try:
            measured.check('ring-down')
        except LumpbeamError:
            continue  # a mode without a usable std says nothing the fit can weigh
        modes.append(measured)
    if not modes:
        return None
    return ModeObservation(
        np.asarray(rest.angles_rad), tuple(modes), f'ring-down at {rest.start_s:.3f} s'
    )


class ArmLearner:
    """Collects ring-downs and fits the arm after each.

    Args:
        arm: The arm file's arm: the nominal values (and the payload, when fitting links).
        fit_payload: Fit the payload (the links as ``arm`` gives them) instead of the links.
        ring_down_s: How long a ring-down must have lasted to be taken, s.
    """

    def __init__(self, arm: ArmConfig, fit_payload: bool = False, ring_down_s: float = 3.0):
        if not (math.isfinite(ring_down_s) and ring_down_s > 0.0):
            raise LumpbeamError(f'ring-down length must be positive, got {ring_down_s!r}')
        self.arm = arm
        self.fit_payload = fit_payload
        self.ring_down_s = ring_down_s
        self.observations: list[ModeObservation] = []
        self._taken: float | None = None
        self._determined = False  # a fit of the ring-downs kept was OK

    def clear(self) -> None:
        """Forgets the ring-downs (a clock jumping back)."""
        self.observations.clear()
        self._taken = None
        self._determined = False

    def offer(self, rest: JointRest | None, result: Identification) -> ArmEstimate | None:
        """Takes the current ring-down's identification; fits when a ring-down is complete.

        Args:
            rest: The joints' current rest (``None`` before any).
            result: The identification of the window, from the rest's start.

        Returns:
            A new estimate when this call took a ring-down, else ``None``. It is a WARN one,
            the ring-down left out, when it has another number of joints than the arm or when
            the arm was determined without it and is not with it (a mode read from noise).
        """
        if (
            rest is None
            or not rest.after_move
            or rest.moved_again
            or rest.duration_s < self.ring_down_s
            or rest.start_s == self._taken
            or result.status == Status.ERROR
        ):
            return None
        if len(rest.angles_rad) != self.arm.n_joints:
            self._taken = rest.start_s
            return ArmEstimate(
                Status.WARN,
                f'a ring-down of {len(rest.angles_rad)} joint(s) left out: the arm file '
                f'{self.arm.source or ""} has {self.arm.n_joints}',
                len(self.observations),
            )
        observation = observation_of(rest, result)
        if observation is None:
            return None
        self._taken = rest.start_s
        self.observations.append(observation)
        estimate = self.fit()
        if self._determined and estimate.status != Status.OK:
            # A mode read from the noise of a well shaped move must not undo what the
            # ring-downs before it determined: that ring-down goes, the arm stays.
            self.observations.pop()
            estimate = ArmEstimate(
                Status.WARN,
                f'{observation.label} left out: with it, {estimate.message}',
                len(self.observations),
            )
        self._determined = self._determined or estimate.status == Status.OK
        del self.observations[:-MAX_RING_DOWNS]
        return estimate

    def fit(self) -> ArmEstimate:
        """The fit of every ring-down taken so far (WARN, with the reason, when it fails).

        A fit whose values :func:`arm_from_status` would refuse (a std larger than its value,
        say) is a WARN too: the shaper and the simulator refuse it, so it is never OK.
        """
        estimate = self._fit()
        if estimate.status == Status.OK:
            try:
                arm_from_status(int(Status.OK), dict(estimate.key_values()), self.arm)
            except LumpbeamError as exc:
                return ArmEstimate(
                    Status.WARN,
                    f'not determined: {estimate.message}, but {exc}',
                    estimate.ring_downs,
                )
        return estimate

    def _fit(self) -> ArmEstimate:
        count = len(self.observations)
        try:
            if self.fit_payload:
                payload = PayloadFit(self.arm).fit(self.observations)
                return ArmEstimate(
                    Status.OK,
                    f'payload fitted to {count} ring-down(s)',
                    count,
                    payload=(payload.payload_kg, payload.payload_kg_std),
                    arm=payload.arm,
                )
            links = LinkParameterFit(self.arm).fit(self.observations)
        except LumpbeamError as exc:
            return ArmEstimate(Status.WARN, f'not determined yet: {exc}', count)
        return ArmEstimate(
            Status.OK,
            f'links fitted to {count} ring-down(s)',
            count,
            links=links.links,
            arm=links.arm,
        )


def _figure(values: Mapping[str, str], key: str) -> tuple[float, float]:
    """A value and its std from the KeyValues, both finite, the std within the value."""
    try:
        value, std = float(values[key]), float(values[f'{key}_std'])
    except KeyError as exc:
        raise LumpbeamError(f'{exc.args[0]} missing') from None
    except ValueError:
        raise LumpbeamError(f'{key}: not a number') from None
    if not (math.isfinite(value) and math.isfinite(std) and std >= 0.0):
        raise LumpbeamError(f'{key} {value!r} +- {std!r}: not finite')
    if std > abs(value):
        raise LumpbeamError(f'{key} {value!r}: its std {std!r} is larger than the value')
    return value, std


def arm_from_status(level: int, values: Mapping[str, str], nominal: ArmConfig) -> ArmConfig:
    """The identified arm from a ``lumpbeam/arm`` status, the rest from the arm file.

    Args:
        level: The status's level (0 OK, 1 WARN, 2 ERROR).
        values: Its KeyValues.
        nominal: The arm file's arm (geometry and masses, and what is not fitted).

    Returns:
        The arm with the published links (or payload).

    Raises:
        LumpbeamError: A level other than OK, a value missing, not finite, a std larger than
            its value, a value the fits cannot give (a stiffness more than
            :data:`~lumpbeam_ros.core.ident.arm.link_fit.MAX_FACTOR` times the file's either
            way, a damping_beta outside [0, :data:`MAX_BETA_S`], a payload negative or above
            :data:`~lumpbeam_ros.core.ident.arm.payload_fit.MAX_PAYLOAD` moving masses), or
            links for another arm.
    """
    if level != int(Status.OK):
        raise LumpbeamError(f'level {level}, not OK: not determined yet')
    if 'payload_kg' in values:
        payload, _ = _figure(values, 'payload_kg')
        heaviest = MAX_PAYLOAD * moving_mass_kg(nominal)
        if not 0.0 <= payload <= heaviest:
            raise LumpbeamError(
                f'payload_kg {payload!r} is outside [0, {heaviest:.6g}] kg (what the fit can give)'
            )
        return nominal.with_payload(payload)
    factors, betas = [], []
    for i, link in enumerate(nominal.links, start=1):
        k, _ = _figure(values, link_key(i, 'k_total_nm_per_rad'))
        beta, _ = _figure(values, link_key(i, 'damping_beta'))
        factor = k / link_stiffness_total(link)
        # The link fit's own bounds: a value past them did not come from it.
        if not (1.0 / MAX_FACTOR <= factor <= MAX_FACTOR) or not 0.0 <= beta <= MAX_BETA_S:
            raise LumpbeamError(
                f'link {i}: k_total {k!r} N m/rad is not within {MAX_FACTOR:g} times the arm '
                f"file's, or damping_beta {beta!r} s is outside [0, {MAX_BETA_S:g}]"
            )
        factors.append(factor)
        betas.append(beta)
    if link_key(nominal.n_joints + 1, 'k_total_nm_per_rad') in values:
        raise LumpbeamError(f"links for more than the arm file's {nominal.n_joints}")
    return scaled_arm(nominal, np.array(factors), np.array(betas))
