"""The payload an arm carries, from the modes measured after its moves (doc/arm.md).

An arm that picks up an unknown part rings slower: the payload, a point mass at the last
link's free end, adds to the mass matrix of B.16 (and, in a vertical arm, to the gravity
terms of its static equilibrium). With the links as the arm file gives them (or as
:class:`~lumpbeam_ros.core.ident.arm.link_fit.LinkParameterFit` identified them), the modes
measured at rest after a move or more pin the payload down: the model's modes at each move's
final joint angles are fitted to the measured ones by weighted least squares, each residual
over its measurement's standard deviation, exactly as the link fit weighs them
(:func:`~lumpbeam_ros.core.ident.arm.link_fit.weighted_residuals`).

The fit refuses, in one line, the two answers that would mislead: a payload the modes ask to
be negative (the links are stiffer, or the arm lighter, than the file says: fit the links
first), and one they cannot determine (configurations where the payload barely moves the
modes).

Example::

    fit = PayloadFit(arm).fit(observations)   # observations: ModeObservation list
    fit.payload_kg, fit.payload_kg_std
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.arm.link_fit import (
    FitData,
    ModeObservation,
    match_all,
    solve_matched,
    weighted_residuals,
)
from lumpbeam_ros.core.model.arm.config import ArmConfig
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.statics import arm_modes
from lumpbeam_ros.core.model.modes import Modes

#: A payload whose std exceeds this fraction of the arm's moving mass (links, joint masses
#: past joint 1) is not determined by the data.
UNDETERMINED_ABOVE = 0.1
#: Standard deviations (the measurements' own, before any scaling by the misfit) below zero
#: from which a payload the modes ask for is refused as negative (closer to zero, it is
#: reported as zero, give or take its std).
NEGATIVE_BEYOND_STD = 2.0
#: A reduced chi^2 above this is a model that does not match the modes with any payload.
POOR_MATCH_ABOVE = 10.0
#: The largest payload fitted, in moving masses of the arm.
MAX_PAYLOAD = 100.0
#: Payloads, in moving masses, whose matched frequencies are compared for the start.
_START_PAYLOADS = np.concatenate([[0.0], np.geomspace(1e-3, 10.0, 41)])


@dataclass(frozen=True)
class PayloadEstimate:
    """The fitted payload and how well the model then matches the measurements.

    Attributes:
        payload_kg: The payload, kg.
        payload_kg_std: Its standard deviation, kg.
        arm: The arm with that payload.
        chi2: Sum of squared weighted residuals at the solution.
        dof: Measured values (two per matched mode) minus one.
        matches: For each observation, the (0-based) model mode of each measured mode.
    """

    payload_kg: float
    payload_kg_std: float
    arm: ArmConfig
    chi2: float
    dof: int
    matches: tuple[tuple[int, ...], ...]

    def warnings(self) -> list[str]:
        """A line when the model matches the modes poorly at the fitted payload."""
        if self.dof <= 0 or self.chi2 / self.dof <= POOR_MATCH_ABOVE:
            return []
        return [
            f'the model matches the modes poorly with any payload (reduced chi^2 '
            f'{self.chi2 / self.dof:.3g}): the links may differ from the arm file; the std is '
            'scaled by the misfit'
        ]

    def as_json(self) -> dict[str, Any]:
        """``payload_kg`` and ``payload_kg_std`` as the contract names them, then the fit's."""
        return {
            'payload_kg': self.payload_kg,
            'payload_kg_std': self.payload_kg_std,
            'chi2': self.chi2,
            'dof': self.dof,
            'reduced_chi2': self.chi2 / self.dof if self.dof > 0 else None,
            'mode_matches': [list(m) for m in self.matches],
        }


def moving_mass_kg(arm: ArmConfig) -> float:
    """The mass the joints move: every link, and every joint mass but joint 1's (on the axis)."""
    return sum(link.mass_kg for link in arm.links) + sum(
        link.joint_mass_kg for link in arm.links[1:]
    )


class PayloadFit:
    """Fits the payload mass to modes measured in one configuration or more.

    Args:
        arm: The arm (links, geometry and masses kept; its payload is the starting point).
    """

    def __init__(self, arm: ArmConfig):
        self.arm = arm
        self.scale_kg = moving_mass_kg(arm)
        self.result_: PayloadEstimate | None = None

    def fit(self, observations: Sequence[ModeObservation]) -> PayloadEstimate:
        """Fits the payload.

        Args:
            observations: One per move (bag): its final joint angles and measured modes.

        Returns:
            The fit, also kept as ``self.result_``.

        Raises:
            LumpbeamError: What :meth:`FitData.checked` refuses, a bag with more modes than
                the model has, a payload the modes ask to be negative, or one they cannot
                determine.
        """
        data = FitData.checked(self.arm, observations, 'payload fit')
        payload, matches = solve_matched(
            self._start(data),
            lambda x, m: self._solve(x, data, m),
            lambda x: match_all(data, self._modes(x, data)),
            'payload fit',
        )
        residual = weighted_residuals(data, self._modes(payload, data), matches)
        slope = self._slope(payload, data, matches)
        information = float(slope @ slope)
        chi2 = float(residual @ residual)
        dof = residual.size - 1
        scale = math.sqrt(max(1.0, chi2 / dof)) if dof > 0 else 1.0
        own_std = 1.0 / math.sqrt(information) if information > 0.0 else math.inf
        std = scale * own_std
        self._check_determined(std, len(data.qs))
        if payload == 0.0:
            # At the bound: the unbounded solution one Gauss-Newton step below zero.
            wanted = -float(slope @ residual) / information
            if wanted < -NEGATIVE_BEYOND_STD * own_std:
                raise LumpbeamError(
                    f'payload fit: the modes of {len(data.qs)} bag(s) ask for a negative '
                    f'payload ({wanted:.3g} +- {std:.2g} kg): the links are stiffer, or the '
                    f'arm lighter, than {self.arm.source or "the arm file"} says; fit the '
                    'links first (--fit-links) with the payload known'
                )
        self.result_ = PayloadEstimate(
            payload_kg=payload,
            payload_kg_std=std,
            arm=self.arm.with_payload(payload),
            chi2=chi2,
            dof=dof,
            matches=tuple(matches),
        )
        return self.result_

    def _start(self, data: FitData) -> float:
        """The payload of :data:`_START_PAYLOADS` whose matched frequencies fit best.

        A local solver started far off (a file without the part picked up) stalls: the modes
        matched there are not the ones matched at the solution.
        """
        best, best_cost = self.arm.payload_kg, math.inf
        for payload in _START_PAYLOADS * self.scale_kg:
            try:
                all_modes = self._modes(float(payload), data)
                matches = match_all(data, all_modes)
            except LumpbeamError:
                continue  # the arm cannot stand with that payload, or has too few modes
            residual = weighted_residuals(data, all_modes, matches)
            cost = float(residual @ residual)
            if cost < best_cost:
                best, best_cost = float(payload), cost
        return best

    def _modes(self, payload_kg: float, data: FitData) -> list[Modes]:
        model = ArmModel.from_config(self.arm.with_payload(payload_kg))
        return [arm_modes(model, q) for q in data.qs]

    def _residuals(
        self, payload_kg: float, data: FitData, matches: Sequence[tuple[int, ...]]
    ) -> np.ndarray:
        return weighted_residuals(data, self._modes(payload_kg, data), matches)

    def _solve(
        self, payload_kg: float, data: FitData, matches: Sequence[tuple[int, ...]]
    ) -> float:
        """Least squares in the payload from ``payload_kg``, kept non-negative."""
        high = MAX_PAYLOAD * self.scale_kg

        def residuals(x: np.ndarray) -> np.ndarray:
            try:
                return self._residuals(float(x[0]), data, matches)
            except LumpbeamError:  # the arm cannot stand with that payload: step back
                return np.full(2 * sum(len(m) for m in data.measured), 1e6)

        solution = least_squares(
            residuals,
            [min(max(payload_kg, 0.0), high)],
            bounds=([0.0], [high]),
            x_scale=[self.scale_kg],
            diff_step=[1e-6],
            method='trf',
            xtol=1e-12,
            ftol=1e-12,
            gtol=1e-12,
            max_nfev=100,
        )
        value = float(solution.x[0])
        # trf stays strictly inside its bounds: a solution pressed against zero is zero.
        return 0.0 if value < 1e-9 * self.scale_kg else value

    def _slope(
        self, payload_kg: float, data: FitData, matches: Sequence[tuple[int, ...]]
    ) -> np.ndarray:
        """d(weighted residuals)/d(payload), one-sided upward at zero, per kg."""
        step = 1e-4 * self.scale_kg
        up = self._residuals(payload_kg + step, data, matches)
        if payload_kg < step:
            return np.asarray((up - self._residuals(payload_kg, data, matches)) / step)
        down = self._residuals(payload_kg - step, data, matches)
        return np.asarray((up - down) / (2.0 * step))

    def _check_determined(self, std_kg: float, n_bags: int) -> None:
        """Refuses a payload the data leave uncertain by more than :data:`UNDETERMINED_ABOVE`."""
        if std_kg <= UNDETERMINED_ABOVE * self.scale_kg:
            return
        raise LumpbeamError(
            f'payload fit: the modes of {n_bags} bag(s) do not determine the payload '
            f"(+- {std_kg:.3g} kg, more than {100 * UNDETERMINED_ABOVE:.0f} % of the arm's "
            f'{self.scale_kg:.3g} kg moving mass): add bags whose moves end in configurations '
            'where the outer link stands out, or that show more modes'
        )
