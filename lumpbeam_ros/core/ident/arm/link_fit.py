"""Each link's stiffness and damping from the modes measured after moves (doc/arm.md).

An arm's modes change with its configuration: in a vertical arm gravity stiffens or softens
each spring by ``g G sin(phi)``, and in any arm of two links or more the mass matrix turns
with the relative joint angles. Modes measured at rest in several configurations therefore
pin down each link's total stiffness k_tE (B.12, B.13) and its damping ``beta = c / k``
(B.23), which one configuration can only when it shows at least one mode per link: the
model's modes (statics, then B.16 linearized about the rest at the final joint angles q) are
fitted to the measured ones by weighted nonlinear least squares, each residual over the
measurement's standard deviation (a frequency's with :data:`FREQUENCY_FLOOR` of the model's
own added).

The unknowns are log factors on the nominal arm's values, one for each link's stiffness and
one for its damping, so both stay positive and the solver sees relative changes. A link given
by ``k_total_nm_per_rad`` has it scaled; a link given by ``ei_nm2`` has its whole EI list
scaled by one factor and reports ``k_total_nm_per_rad`` as its first spring over
``n_segments`` (``2 EI_1 / L_s / n_s``: k_tE of a uniform link, 2 EI / L).

Measured modes are matched to model modes by frequency, keeping their order (a bag may lack
a mode the camera did not see): first at the common stiffness factor that matches the
measured frequencies best (a grid from 1/3 to 3 times nominal), then again at each solution
until the matching no longer changes.

Example::

    fit = LinkParameterFit(arm).fit(observations)   # observations: ModeObservation list
    fit.links[0].k_total_nm_per_rad, fit.links[0].k_total_nm_per_rad_std
    predicted = fit.predict(q)                      # the fitted arm's modes at q
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, fields, replace
from typing import Any, TypeVar

import numpy as np
from scipy.optimize import least_squares

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.identification import IdentifiedMode
from lumpbeam_ros.core.model.adopt import MAX_STIFFNESS_FACTOR
from lumpbeam_ros.core.model.arm.config import ArmConfig, LinkConfig
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.statics import arm_modes
from lumpbeam_ros.core.model.modes import Modes

#: How far from nominal a factor may go (the solver's bounds on the log factors): as far as
#: the simulator lets an identified stiffness go from its model's.
MAX_FACTOR = MAX_STIFFNESS_FACTOR
#: Common stiffness factors tried for the first matching of measured to model modes.
START_FACTORS = np.exp(np.linspace(math.log(1 / 3), math.log(3), 49))
#: Relative step of the central differences behind the covariance.
_STEP = 1e-5
#: A parameter whose direction in the weighted Jacobian is this small (relative to the
#: largest singular value) is not determined by the data.
_RANK_TOLERANCE = 1e-6
#: How closely, relative, the linearized model about the rest can match a measured frequency:
#: added in quadrature to each measured frequency's std. A ring-down's first mode is often
#: measured finer than this, while its frequency departs from the small-amplitude model's by
#: about 6e-6 (the three-link arm after the lab's campaign moves, ``python -m
#: lumpbeam_lab.arm_links --bags``); weighted at its own std it would claim the first link's
#: stiffness tighter than it is.
FREQUENCY_FLOOR = 1e-5
#: A stiffness or damping whose relative std exceeds this is reported as uncertain.
UNCERTAIN_ABOVE = 0.05
#: The weighted residual of a mode the model no longer has.
_FAR = 1e6
#: Rounds of fit-then-rematch before the matching must have settled.
_MAX_ROUNDS = 4


@dataclass(frozen=True)
class MeasuredMode:
    """One mode identified in a ring-down, with standard deviations.

    Attributes:
        natural_frequency_hz: f_n, Hz.
        natural_frequency_hz_std: Its standard deviation, Hz (> 0).
        damping_ratio: zeta.
        damping_ratio_std: Its standard deviation (> 0).
    """

    natural_frequency_hz: float
    natural_frequency_hz_std: float
    damping_ratio: float
    damping_ratio_std: float

    @classmethod
    def of(cls, mode: IdentifiedMode) -> MeasuredMode:
        """A mode as the identification gives it (its std NaN where it has none)."""
        return cls(
            mode.natural_frequency_hz.value,
            mode.natural_frequency_hz.std,
            mode.damping_ratio.value,
            mode.damping_ratio.std,
        )

    @classmethod
    def from_json(cls, entry: Mapping[str, Any], where: str) -> MeasuredMode:
        """A mode from an entry of ``lumpbeam analyze``'s ``modes`` list (extra keys ignored).

        Raises:
            LumpbeamError: A key missing, or a value that is not a number (null: no
                estimate).
        """
        values = []
        for key in (f.name for f in fields(cls)):
            value = entry.get(key)
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise LumpbeamError(f'{where}: {key} is {value!r}, not a number')
            values.append(float(value))
        return cls(*values)

    def check(self, where: str) -> None:
        """Refuses a mode that cannot be fitted.

        Raises:
            LumpbeamError: A frequency that is not positive, a damping ratio outside [0, 1),
                a standard deviation that is not positive and finite.
        """
        f, zeta = self.natural_frequency_hz, self.damping_ratio
        if not (math.isfinite(f) and f > 0.0):
            raise LumpbeamError(f'{where}: natural frequency {f!r} Hz is not positive')
        if not (math.isfinite(zeta) and 0.0 <= zeta < 1.0):
            raise LumpbeamError(f'{where}: damping ratio {zeta!r} is outside [0, 1)')
        for name, std in (
            ('natural_frequency_hz_std', self.natural_frequency_hz_std),
            ('damping_ratio_std', self.damping_ratio_std),
        ):
            if not (math.isfinite(std) and std > 0.0):
                raise LumpbeamError(f'{where}: {name} {std!r} is not positive and finite')


@dataclass(frozen=True)
class ModeObservation:
    """The modes measured after one move, and the joint angles the move ended at.

    Attributes:
        joint_angles_rad: q at rest, rad, one per joint.
        modes: The modes measured (any number, any subset of the arm's modes).
        label: Where they come from (a bag), for messages.
    """

    joint_angles_rad: np.ndarray
    modes: tuple[MeasuredMode, ...]
    label: str = ''

    def sorted_modes(self) -> tuple[MeasuredMode, ...]:
        """The modes by increasing frequency."""
        return tuple(sorted(self.modes, key=lambda m: m.natural_frequency_hz))


@dataclass(frozen=True)
class LinkEstimate:
    """One link's fitted values, as ``lumpbeam analyze --fit-links`` lists them.

    Attributes:
        k_total_nm_per_rad: k_tE, N m/rad.
        k_total_nm_per_rad_std: Its standard deviation.
        damping_beta: ``c / k`` of every spring, s.
        damping_beta_std: Its standard deviation.
    """

    k_total_nm_per_rad: float
    k_total_nm_per_rad_std: float
    damping_beta: float
    damping_beta_std: float

    def as_dict(self) -> dict[str, float]:
        """The JSON entry."""
        return {
            'k_total_nm_per_rad': self.k_total_nm_per_rad,
            'k_total_nm_per_rad_std': self.k_total_nm_per_rad_std,
            'damping_beta': self.damping_beta,
            'damping_beta_std': self.damping_beta_std,
        }


@dataclass(frozen=True)
class LinkFit:
    """The fitted links and how well the model then matches the measurements.

    Attributes:
        links: Joint 1 outward.
        arm: The arm with the fitted values.
        chi2: Sum of squared weighted residuals at the solution.
        dof: Measurements (two per matched mode) minus unknowns (two per link).
        matches: For each observation, the (0-based) model mode each measured mode (by
            increasing frequency) was matched to.
        std_scale: Factor applied to the covariance's standard deviations:
            ``sqrt(max(1, chi2 / dof))`` (1 without spare measurements).
        evaluations: Model evaluations (statics and modes at every configuration).
    """

    links: tuple[LinkEstimate, ...]
    arm: ArmConfig
    chi2: float
    dof: int
    matches: tuple[tuple[int, ...], ...]
    std_scale: float
    evaluations: int = 0
    covariance: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))

    def predict(self, q: np.ndarray) -> Modes:
        """The fitted arm's modes at rest at joint angles ``q``."""
        return arm_modes(ArmModel.from_config(self.arm), q)

    def warnings(self) -> list[str]:
        """One line per stiffness or damping uncertain by more than :data:`UNCERTAIN_ABOVE`.

        Each line says what data would pin it down. The fit is kept: its standard deviation
        says how uncertain it is. A link's damping comes from the damping ratios of the modes
        that bend it, which a smooth move leaves too weak to measure for the higher modes
        (doc/arm.md).
        """
        lines = []
        for i, link in enumerate(self.links, start=1):
            relative = link.k_total_nm_per_rad_std / link.k_total_nm_per_rad
            if relative > UNCERTAIN_ABOVE:
                lines.append(
                    f"link {i}'s stiffness is uncertain by {100 * relative:.0f} %: add bags "
                    'that show more modes, or whose moves end in other configurations'
                )
            relative = link.damping_beta_std / link.damping_beta
            if relative > UNCERTAIN_ABOVE:
                lines.append(
                    f"link {i}'s damping is uncertain by {100 * relative:.0f} %: end each move "
                    'with a short quick step of the outer joint (about 0.03 rad in 0.15 s) so '
                    'that every mode rings, and add bags whose moves end in other '
                    'configurations'
                )
        return lines

    def as_json(self) -> dict[str, Any]:
        """``links`` as the contract lists them, then the fit's figures."""
        return {
            'links': [link.as_dict() for link in self.links],
            'chi2': self.chi2,
            'dof': self.dof,
            'reduced_chi2': self.chi2 / self.dof if self.dof > 0 else None,
            'mode_matches': [list(m) for m in self.matches],
        }


def link_stiffness_total(link: LinkConfig) -> float:
    """A link's k_tE: its own, or its first spring over ``n_segments`` for an EI link."""
    if link.k_total_nm_per_rad is not None:
        return link.k_total_nm_per_rad
    return float(link.spring_stiffness()[0]) / link.n_segments


def scaled_arm(arm: ArmConfig, stiffness: np.ndarray, beta: np.ndarray) -> ArmConfig:
    """The arm with each link's stiffness scaled and its damping set.

    Args:
        arm: The nominal arm.
        stiffness: One factor per link on k_tE (or on the whole EI list).
        beta: Each link's ``damping_beta``, s.

    Returns:
        The new arm.
    """
    links = []
    for link, factor, b in zip(arm.links, stiffness, beta, strict=True):
        if link.k_total_nm_per_rad is not None:
            link = replace(link, k_total_nm_per_rad=link.k_total_nm_per_rad * float(factor))
        else:
            assert link.ei_nm2 is not None
            link = replace(link, ei_nm2=tuple(e * float(factor) for e in link.ei_nm2))
        links.append(replace(link, damping_beta=float(b)))
    return replace(arm, links=tuple(links))


def match_modes(measured_hz: np.ndarray, model_hz: np.ndarray) -> tuple[int, ...] | None:
    """Assigns measured modes to model modes in order, nearest in log frequency.

    Dynamic programming over increasing assignments: measured mode i (by increasing
    frequency) goes to model mode ``j_i`` with ``j_1 < j_2 < ...``, minimising the sum of
    ``log(f_i / g_{j_i})^2``; a model mode may go unmatched (not seen in the data).

    Args:
        measured_hz: Measured frequencies, increasing.
        model_hz: Model frequencies, increasing.

    Returns:
        The model index of each measured mode, or ``None`` when the model has fewer modes.
    """
    m, n = measured_hz.size, model_hz.size
    if m > n:
        return None
    cost = (np.log(measured_hz)[:, None] - np.log(model_hz)[None, :]) ** 2
    best = np.full((m + 1, n + 1), math.inf)
    best[0, :] = 0.0
    for i in range(1, m + 1):
        for j in range(i, n + 1):
            best[i, j] = min(best[i, j - 1], best[i - 1, j - 1] + cost[i - 1, j - 1])
    picks: list[int] = []
    j = n
    for i in range(m, 0, -1):
        while j > i and best[i, j - 1] <= best[i - 1, j - 1] + cost[i - 1, j - 1]:
            j -= 1
        picks.append(j - 1)
        j -= 1
    return tuple(reversed(picks))


@dataclass(frozen=True)
class FitData:
    """The observations as a fit of the arm's model to them uses them.

    Attributes:
        qs: Each observation's final joint angles.
        measured: Each observation's modes by increasing frequency.
        labels: Each observation's label, for messages.
    """

    qs: tuple[np.ndarray, ...]
    measured: tuple[tuple[MeasuredMode, ...], ...]
    labels: tuple[str, ...]

    @classmethod
    def checked(cls, arm: ArmConfig, observations: Sequence[ModeObservation], fit: str) -> FitData:
        """The observations, checked against the arm.

        Args:
            arm: The arm they were measured on.
            observations: One per move (bag).
            fit: What is fitted (``'link fit'``), for messages.

        Raises:
            LumpbeamError: No observations, angles for another arm, an observation without
                modes, a bad measured mode.
        """
        if not observations:
            raise LumpbeamError(f'{fit}: no measured modes to fit')
        model = ArmModel.from_config(arm)
        qs, measured, labels = [], [], []
        for k, o in enumerate(observations):
            where = o.label or f'observation {k + 1}'
            qs.append(model.check_angles(o.joint_angles_rad, f'{where}: final joint angles'))
            if not o.modes:
                raise LumpbeamError(f'{where}: no mode measured')
            for i, mode in enumerate(o.modes):
                mode.check(f'{where}: mode {i + 1}')
            measured.append(o.sorted_modes())
            labels.append(where)
        return cls(tuple(qs), tuple(measured), tuple(labels))

    @property
    def frequencies(self) -> list[np.ndarray]:
        """Each observation's measured frequencies, increasing."""
        return [np.array([m.natural_frequency_hz for m in ms]) for ms in self.measured]

    @property
    def n_values(self) -> int:
        """Measured values: a frequency and a damping ratio per mode."""
        return 2 * sum(len(ms) for ms in self.measured)


def match_all(data: FitData, all_modes: Sequence[Modes]) -> list[tuple[int, ...]]:
    """Each observation's measured modes matched to the model's there (:func:`match_modes`).

    Raises:
        LumpbeamError: An observation with more modes than the model has.
    """
    matches = []
    for f, m, label in zip(data.frequencies, all_modes, data.labels, strict=True):
        match = match_modes(f, m.natural_frequency_hz)
        if match is None:
            raise LumpbeamError(
                f'{label}: {f.size} modes measured, more than the arm model has '
                f'({m.natural_frequency_hz.size})'
            )
        matches.append(match)
    return matches


def weighted_residuals(
    data: FitData, all_modes: Sequence[Modes], matches: Sequence[tuple[int, ...]]
) -> np.ndarray:
    """Each matched mode's frequency and damping-ratio misfit over its std.

    Args:
        data: The observations.
        all_modes: The model's modes at each observation's joint angles.
        matches: Each observation's matching (:func:`match_all`).

    Returns:
        Two values per matched mode, observation by observation.
    """
    parts = []
    for modes, ms, match in zip(all_modes, data.measured, matches, strict=True):
        for mode, j in zip(ms, match, strict=True):
            if j >= modes.natural_frequency_hz.size:
                # The mode turned overdamped or vanished: as far off as it can be.
                parts += [_FAR, _FAR]
                continue
            f = mode.natural_frequency_hz
            df = modes.natural_frequency_hz[j] - f
            dz = modes.damping_ratio[j] - mode.damping_ratio
            f_std = math.hypot(mode.natural_frequency_hz_std, FREQUENCY_FLOOR * f)
            parts += [df / f_std, dz / mode.damping_ratio_std]
    return np.asarray(parts, dtype=float)


_X = TypeVar('_X')
Matches = list[tuple[int, ...]]


def solve_matched(
    start: _X,
    solve: Callable[[_X, Matches], _X],
    match: Callable[[_X], Matches],
    fit: str,
) -> tuple[_X, Matches]:
    """Solves with the matching held, then matches again at the solution, until it settles.

    Args:
        start: The unknowns to start from.
        solve: The solution from unknowns, the matching held.
        match: The matching of measured to model modes at given unknowns.
        fit: What is fitted (``'link fit'``), for messages.

    Returns:
        The solution and its matching.

    Raises:
        LumpbeamError: The matching still changes after :data:`_MAX_ROUNDS` solutions.
    """
    x, matches = start, match(start)
    for _ in range(_MAX_ROUNDS):
        x = solve(x, matches)
        rematched = match(x)
        if rematched == matches:
            return x, matches
        matches = rematched
    raise LumpbeamError(
        f'{fit}: the measured modes match different model modes at every solution; '
        'check that the bags come from this arm'
    )


class LinkParameterFit:
    """Fits each link's k_tE and ``damping_beta`` to modes measured in several configurations.

    Args:
        arm: The nominal arm (geometry and masses are kept; stiffness and damping are the
            starting point).
    """

    def __init__(self, arm: ArmConfig):
        self.arm = arm
        self.n_links = arm.n_joints
        self._evaluations = 0
        self._beta0 = np.array([link.damping_beta for link in arm.links])
        self.result_: LinkFit | None = None

    def fit(self, observations: Sequence[ModeObservation]) -> LinkFit:
        """Fits the links.

        Args:
            observations: One per move (bag): its final joint angles and measured modes.

        Returns:
            The fit, also kept as ``self.result_``.

        Raises:
            LumpbeamError: No observations, angles for another arm, a bad measured mode,
                fewer measured modes in all than links (the problem is underdetermined), a
                bag with more modes than the model has, or data that leave a link's
                stiffness or damping undetermined (configurations too alike).
        """
        data = FitData.checked(self.arm, observations, 'link fit')
        self._check_count(data)
        self._beta0 = self._beta_start(data)
        n = self.n_links
        theta = np.zeros(2 * n)
        theta[:n] = self._common_start(data)
        theta, matches = solve_matched(
            theta,
            lambda x, m: self._solve(x, data, m),
            lambda x: self._match(x, data),
            'link fit',
        )
        residual = self._residuals(theta, data, matches)
        jac = self._jacobian(theta, data, matches)
        self._check_rank(jac, len(data.qs))
        chi2 = float(residual @ residual)
        dof = residual.size - theta.size
        scale = math.sqrt(max(1.0, chi2 / dof)) if dof > 0 else 1.0
        covariance = np.linalg.inv(jac.T @ jac) * scale**2
        std = np.sqrt(np.diag(covariance))
        arm = self._arm(theta, data)
        links = []
        for i, link in enumerate(arm.links):
            k = link_stiffness_total(link)
            links.append(
                LinkEstimate(
                    k_total_nm_per_rad=k,
                    k_total_nm_per_rad_std=k * float(std[i]),
                    damping_beta=link.damping_beta,
                    damping_beta_std=link.damping_beta * float(std[n + i]),
                )
            )
        self.result_ = LinkFit(
            links=tuple(links),
            arm=arm,
            chi2=chi2,
            dof=dof,
            matches=tuple(matches),
            std_scale=scale,
            evaluations=self._evaluations,
            covariance=covariance,
        )
        return self.result_

    def predict(self, q: np.ndarray) -> Modes:
        """The fitted arm's modes at ``q``.

        Raises:
            LumpbeamError: Not fitted yet, or bad angles.
        """
        if self.result_ is None:
            raise LumpbeamError('link fit: predict before fit')
        return self.result_.predict(q)

    def _check_count(self, data: FitData) -> None:
        """Refuses fewer measured modes than links."""
        total = sum(len(ms) for ms in data.measured)
        if total < self.n_links:
            raise LumpbeamError(
                f'link fit: {len(data.qs)} bag(s) give {total} mode(s) in all, but the '
                f'{self.n_links} links need at least {self.n_links} (one frequency and one '
                'damping ratio per unknown stiffness and damping): add bags whose moves end '
                'in other configurations'
            )

    def _beta_start(self, data: FitData) -> np.ndarray:
        """The nominal betas; a link without damping starts at ``2 zeta / omega`` of the data.

        For stiffness-proportional damping every mode has ``zeta = beta omega / 2``.
        """
        betas = np.array([link.damping_beta for link in self.arm.links])
        guesses = [
            2.0 * m.damping_ratio / (2.0 * math.pi * m.natural_frequency_hz)
            for modes in data.measured
            for m in modes
        ]
        median = float(np.median(guesses))
        fallback = median if median > 0.0 else 1e-4
        return np.where(betas > 0.0, betas, fallback)

    def _arm(self, theta: np.ndarray, data: FitData) -> ArmConfig:
        """The arm at log factors ``theta`` (stiffness factors, then damping factors)."""
        n = self.n_links
        return scaled_arm(self.arm, np.exp(theta[:n]), self._beta0 * np.exp(theta[n:]))

    def _all_modes(self, theta: np.ndarray, data: FitData) -> list[Modes]:
        model = ArmModel.from_config(self._arm(theta, data))
        self._evaluations += len(data.qs)
        return [arm_modes(model, q) for q in data.qs]

    def _common_start(self, data: FitData) -> float:
        """The common log stiffness factor whose matched frequencies fit best."""
        best, best_cost = 0.0, math.inf
        n = self.n_links
        frequencies = data.frequencies
        for factor in START_FACTORS:
            theta = np.zeros(2 * n)
            theta[:n] = math.log(factor)
            try:
                modes = self._all_modes(theta, data)
            except LumpbeamError:
                continue  # too soft to stand at some q
            cost = 0.0
            for f, m in zip(frequencies, modes, strict=True):
                g = m.natural_frequency_hz
                match = match_modes(f, g)
                if match is None:
                    cost = math.inf
                    break
                cost += float(np.sum(np.log(f / g[list(match)]) ** 2))
            if cost < best_cost:
                best, best_cost = math.log(factor), cost
        if not math.isfinite(best_cost):
            self._match(np.zeros(2 * n), data)  # names the bag with too many modes
            raise LumpbeamError("link fit: the arm cannot stand at the bags' joint angles")
        return best

    def _match(self, theta: np.ndarray, data: FitData) -> list[tuple[int, ...]]:
        return match_all(data, self._all_modes(theta, data))

    def _residuals(
        self, theta: np.ndarray, data: FitData, matches: list[tuple[int, ...]]
    ) -> np.ndarray:
        return weighted_residuals(data, self._all_modes(theta, data), matches)

    def _solve(
        self, theta: np.ndarray, data: FitData, matches: list[tuple[int, ...]]
    ) -> np.ndarray:
        """Least squares in the log factors from ``theta``, the matching held."""
        bound = math.log(MAX_FACTOR)

        def residuals(x: np.ndarray) -> np.ndarray:
            try:
                return self._residuals(x, data, matches)
            except LumpbeamError:  # no equilibrium: the solver steps back
                return np.full(data.n_values, _FAR)

        def jacobian(x: np.ndarray) -> np.ndarray:
            try:
                return self._jacobian(x, data, matches)
            except LumpbeamError:
                return np.zeros((data.n_values, x.size))

        solution = least_squares(
            residuals,
            np.clip(theta, -bound, bound),
            jac=jacobian,
            bounds=(-bound, bound),
            method='trf',
            xtol=1e-10,
            ftol=1e-12,
            gtol=1e-10,
            max_nfev=100,
        )
        return np.asarray(solution.x)

    def _jacobian(
        self, theta: np.ndarray, data: FitData, matches: list[tuple[int, ...]]
    ) -> np.ndarray:
        """Central differences of the weighted residuals in the log factors."""
        columns = []
        for i in range(theta.size):
            step = np.zeros_like(theta)
            step[i] = _STEP
            up = self._residuals(theta + step, data, matches)
            down = self._residuals(theta - step, data, matches)
            columns.append((up - down) / (2 * _STEP))
        return np.column_stack(columns)

    def _check_rank(self, jac: np.ndarray, n_bags: int) -> None:
        """Refuses data that leave a direction of the unknowns undetermined."""
        _, singular, vt = np.linalg.svd(jac, full_matrices=False)
        if singular[-1] > _RANK_TOLERANCE * singular[0]:
            return
        worst = int(np.argmax(np.abs(vt[-1])))
        n = self.n_links
        what = 'stiffness' if worst < n else 'damping'
        raise LumpbeamError(
            f"link fit: the modes of {n_bags} bag(s) do not determine link {worst % n + 1}'s "
            f'{what}: add bags whose moves end in other configurations'
        )
