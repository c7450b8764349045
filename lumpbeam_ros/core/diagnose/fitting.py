"""Least-squares fits of the candidate models to a record, in the time domain.

A model is simulated under the record's own load schedule (``simulate_loads``) and compared
with the measured tip z and pitch, each divided by its noise sigma, so the sum of squares is
a chi-square and both channels count by their information: the pitch carries what separates
a compliant mount from a softer beam (the slope-to-displacement ratio of the tip).

A tracker may take up a new constant bias after losing its target
(:func:`~lumpbeam_ros.core.diagnose.measurement.tracked_segments`): every stretch after the first
is compared up to its own offset in each channel, projected out in closed form (its mean
residual), so it costs no extra search dimension. The first stretch keeps the absolute
level, so a record tracked throughout is compared as it is.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from scipy.optimize import least_squares

from lumpbeam_ros.core.diagnose.measurement import Record
from lumpbeam_ros.core.model.parameters import BeamParameters
from lumpbeam_ros.core.model.simulate import SimulationDivergedError, WarmStart, simulate_loads
from lumpbeam_ros.core.model.trajectory import TipTrajectory

#: Finite-difference step of the fitted parameters, relative to their magnitude (scipy's
#: ``diff_step``; :func:`forward_jacobian`): well above the simulator's round-off and its
#: dry-friction switching, well below any parameter's uncertainty.
DIFF_STEP = 2e-3

#: Tolerances of the fits' least squares on the change of chi2 and of the parameters.
FIT_FTOL = 1e-4
FIT_XTOL = 1e-4

#: Residual of every sample when a model cannot be simulated (extreme parameters): far
#: worse than any fit, so the least squares steps back.
DIVERGED_RESIDUAL = 1e3

#: Residual vectors remembered by model and parameters: a fit's start is often a point the
#: screening simulated before the other candidates' fits, and the final fit on the whole
#: record starts where its training fit was evaluated, rounds earlier. A diagnosis runs a
#: few hundred simulations, so it keeps them all (a few MB).
MEMO_SIZE = 1024

#: Of those, the most recent keep their simulation too (each about 15 times the size of its
#: residuals): a fit's end, simulated for residuals, is then not simulated again for its
#: trajectory.
TRAJECTORY_MEMO_SIZE = 32


class Fittable(Protocol):
    """What a fit needs of a model: a single candidate effect, or several at once."""

    @property
    def name(self) -> str:
        """The model's name."""

    @property
    def n_parameters(self) -> int:
        """Fitted parameters."""

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Bounds of the fitted ``x``."""

    def step_floor(self) -> np.ndarray:
        """Magnitudes of ``x`` below which a finite-difference step stops shrinking."""

    def beam(self, nominal: BeamParameters, x: np.ndarray) -> BeamParameters:
        """The beam that ``x`` describes."""

    def physical(self, x: np.ndarray) -> bool:
        """Whether ``x`` is plausible and off its bounds."""


@dataclass(frozen=True)
class Fit:
    """A candidate fitted to (part of) a record.

    Attributes:
        candidate: The model.
        x: Its fitted parameters (see :meth:`Candidate.beam`).
        beam: The fitted beam.
        chi2: Sum of squared noise-normalized residuals over the fitted samples.
        n_residuals: Number of residuals (samples times two channels).
        evaluations: Simulations the fit took.
        physical: Whether the fitted values are inside their plausible ranges.
        warm: The solver's remainders of the fit's last simulation, to start a nearby
            model's from (:class:`~lumpbeam_ros.core.model.simulate.WarmStart`), or ``None``.
    """

    candidate: Fittable
    x: np.ndarray
    beam: BeamParameters
    chi2: float
    n_residuals: int
    evaluations: int
    physical: bool
    warm: WarmStart | None = None

    @property
    def name(self) -> str:
        """The candidate's name."""
        return self.candidate.name

    @property
    def reduced_chi2(self) -> float:
        """chi2 per residual: 1 when the model explains the data down to the noise."""
        return self.chi2 / self.n_residuals


class FitProblem:
    """A record, its noise levels and the nominal beam that the models are built on.

    Args:
        record: The measurement.
        nominal: The nominal beam in identified form with no effects (the reference of the
            fitted log-parameters).
        sigma_z: Noise of z, m.
        sigma_pitch: Noise of the pitch, rad.
    """

    def __init__(
        self, record: Record, nominal: BeamParameters, sigma_z: float, sigma_pitch: float
    ):
        self.record = record
        # Residuals, and the recent simulations, by model, parameters and end.
        self._memo: dict[tuple[str, bytes, float], np.ndarray] = {}
        self._trajectories: dict[tuple[str, bytes, float], TipTrajectory] = {}
        self._nominal = nominal
        self.sigma_z = sigma_z
        self.sigma_pitch = sigma_pitch
        self.simulations = 0
        self._segments = record.tracked_segments()

    @property
    def nominal(self) -> BeamParameters:
        """The nominal beam the models' parameters refer to."""
        return self._nominal

    @nominal.setter
    def nominal(self, beam: BeamParameters) -> None:
        self._nominal = beam
        # Residuals remembered for the old reference are not the new's.
        self._memo.clear()
        self._trajectories.clear()

    def simulate(
        self, beam: BeamParameters, end_s: float = math.inf, warm: WarmStart | None = None
    ) -> TipTrajectory:
        """Simulates a beam at the record's stamps up to ``end_s``.

        Args:
            beam: The beam.
            end_s: Last time of interest, s.
            warm: Where to start the solver's sweeps from, and to leave this simulation's
                (:class:`~lumpbeam_ros.core.model.simulate.WarmStart`).

        Returns:
            The tip trajectory at the stamps ``t <= end_s``.
        """
        self.simulations += 1
        t = self.record.t[self.record.t <= end_s]
        return simulate_loads(
            beam,
            t,
            self.record.load_events,
            self.record.initial_load_kg,
            stiff_fallback=False,
            warm=warm,
        )

    def model_residuals(
        self,
        model: Fittable,
        x: np.ndarray,
        end_s: float = math.inf,
        warm: WarmStart | None = None,
    ) -> np.ndarray:
        """Residuals of a model at ``x`` on the samples up to ``end_s``.

        A beam the modal solver cannot simulate, or that cannot carry its load (extreme
        parameters), gets
        ``DIVERGED_RESIDUAL`` everywhere: a bad fit, not minutes of a stiff solver.

        Args:
            model: The model.
            x: Its parameters.
            end_s: Last time, s.
            warm: See :meth:`simulate`.

        Returns:
            The stacked residuals (:meth:`residuals`).
        """
        key = self._key(model, x, end_s)
        if key in self._memo:  # e.g. a screening column at the strength a fit starts from
            return self._memo[key].copy()
        trajectory = None
        try:
            with np.errstate(all='ignore'):
                trajectory = self.simulate(model.beam(self.nominal, x), end_s, warm)
            residuals = self.residuals(trajectory)
        except (SimulationDivergedError, RuntimeError):  # RuntimeError: no static equilibrium
            count = int(np.count_nonzero(self.record.t <= end_s))
            residuals = np.full(2 * count, DIVERGED_RESIDUAL)
        self._remember(key, residuals, trajectory)
        return residuals.copy()

    def trajectory(self, model: Fittable, x: np.ndarray, end_s: float = math.inf) -> TipTrajectory:
        """A model's simulation at ``x`` up to ``end_s``, remembered with its residuals.

        One just simulated for residuals (the end of a fit) is not simulated again, and a
        fit that starts at ``x`` (:meth:`fit`) finds the residuals.

        Args:
            model: The model.
            x: Its parameters.
            end_s: Last time, s.

        Returns:
            The tip trajectory.

        Raises:
            SimulationDivergedError: The modal solver cannot simulate the beam.
            RuntimeError: The beam has no static equilibrium.
        """
        key = self._key(model, x, end_s)
        remembered = self._trajectories.get(key)
        if remembered is not None:
            return remembered
        with np.errstate(all='ignore'):
            trajectory = self.simulate(model.beam(self.nominal, x), end_s)
        self._remember(key, self.residuals(trajectory), trajectory)
        return trajectory

    @staticmethod
    def _key(model: Fittable, x: np.ndarray, end_s: float) -> tuple[str, bytes, float]:
        return model.name, np.asarray(x, dtype=float).tobytes(), end_s

    def _remember(
        self,
        key: tuple[str, bytes, float],
        residuals: np.ndarray,
        trajectory: TipTrajectory | None,
    ) -> None:
        if len(self._memo) >= MEMO_SIZE:
            self._memo.pop(next(iter(self._memo)))
        self._memo[key] = residuals
        if trajectory is not None:
            if len(self._trajectories) >= TRAJECTORY_MEMO_SIZE:
                self._trajectories.pop(next(iter(self._trajectories)))
            self._trajectories[key] = trajectory

    def residuals(self, trajectory: TipTrajectory, start_s: float = -math.inf) -> np.ndarray:
        """Noise-normalized residuals (model minus measurement), z then pitch.

        Args:
            trajectory: A simulation at (a prefix of) the record's stamps.
            start_s: Only samples at or after this time.

        Returns:
            The stacked residuals.
        """
        n = len(trajectory)
        keep = self.record.t[:n] >= start_s
        rz = (trajectory.z[keep] - self.record.z[:n][keep]) / self.sigma_z
        rp = (trajectory.pitch[keep] - self.record.pitch[:n][keep]) / self.sigma_pitch
        return np.concatenate([self._debias(rz, keep), self._debias(rp, keep)])

    def _debias(self, residual: np.ndarray, keep: np.ndarray) -> np.ndarray:
        """Removes each later tracked stretch's own offset (the first one is the reference)."""
        labels = self._segments[: keep.size][keep]
        if labels.size == 0 or labels[-1] == 0:
            return residual
        counts = np.bincount(labels)
        means = np.bincount(labels, weights=residual) / np.maximum(counts, 1)
        means[0] = 0.0
        return np.asarray(residual - means[labels])

    def fit(
        self,
        candidate: Fittable,
        x0: np.ndarray,
        end_s: float = math.inf,
        max_evaluations: int = 60,
        alternatives: Sequence[np.ndarray] = (),
        warm: WarmStart | None = None,
    ) -> Fit:
        """Fits a candidate by bounded least squares on the samples up to ``end_s``.

        Args:
            candidate: The model.
            x0: Starting parameters (clipped into the bounds).
            end_s: Last fitted time, s.
            max_evaluations: Budget of residual evaluations (each one simulation).
            alternatives: Other starting points (e.g. a linearized step's prediction):
                the fit starts from whichever of them and ``x0`` has the lowest chi2.
            warm: Where the first simulation's sweeps start (a copy is taken; e.g. the
                fit of the model this one extends): same result, fewer sweeps.

        Returns:
            The fit.
        """
        lo, hi = candidate.bounds()
        start = self.simulations
        # Each evaluation starts from the previous one's solution.
        warm = WarmStart() if warm is None else warm.copy()

        def fun(x: np.ndarray) -> np.ndarray:
            return self.model_residuals(candidate, x, end_s, warm)

        def column(x: np.ndarray) -> np.ndarray:
            # A Jacobian column's sweeps start from the point's own remainders (one
            # finite-difference step away), not from the previous column's (two): fewer
            # sweeps, and the next step starts from the point's too. With none yet (the
            # point was remembered, not simulated), the first column leaves its own.
            return self.model_residuals(candidate, x, end_s, warm.copy() if warm else warm)

        jacobian = _FinalJacobian(fun, lo, hi, candidate.step_floor(), column)

        starts = [
            np.clip(np.asarray(x, dtype=float), lo + 1e-9, hi - 1e-9) for x in (x0, *alternatives)
        ]
        x0 = (
            min(starts, key=lambda x: float(np.sum(fun(x) ** 2))) if len(starts) > 1 else starts[0]
        )

        result = least_squares(
            fun,
            x0,
            bounds=(lo, hi),
            jac=jacobian,
            x_scale=1.0,
            max_nfev=max_evaluations,
            xtol=FIT_XTOL,
            ftol=FIT_FTOL,
        )
        return Fit(
            candidate=candidate,
            x=result.x,
            beam=candidate.beam(self.nominal, result.x),
            chi2=float(2.0 * result.cost),
            n_residuals=int(result.fun.size),
            evaluations=self.simulations - start,
            physical=candidate.physical(result.x),
            warm=warm,
        )


#: Step of a finite difference at a parameter of 0, where a relative step is none (scipy's
#: for forward differences: the square root of the machine epsilon).
ZERO_STEP = float(np.sqrt(np.finfo(float).eps))


def forward_jacobian(
    fun: Callable[[np.ndarray], np.ndarray],
    x: np.ndarray,
    f0: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    floor: np.ndarray | None = None,
) -> np.ndarray:
    """Forward-difference Jacobian, with the steps of scipy's ``'2-point'`` scheme.

    The step is ``DIFF_STEP`` relative (``ZERO_STEP`` at 0), towards larger magnitudes,
    turned back when it would leave the bounds, shortened when neither direction fits.

    A step relative to the parameter alone vanishes with it: at an effect's strength of
    1e-9 (off, on its bound) it is 2e-12, whose residual change is the simulator's
    tolerance (its sweeps start warm from the previous simulation), not the slope; a fit
    there moved or stayed on that noise, and a diagnosis flipped on a change of the
    noise estimate in its 14th digit. So the magnitude a step is relative to is at least
    ``floor`` (the candidates' starting strengths, felt by the data).

    Args:
        fun: The residuals.
        x: Where.
        f0: ``fun(x)``.
        lo: Lower bounds.
        hi: Upper bounds.
        floor: Per parameter, the magnitude below which the step stops shrinking
            (``None``: none, scipy's steps).

    Returns:
        The Jacobian, (f0.size, x.size).
    """
    sign = np.where(x >= 0.0, 1.0, -1.0)
    magnitude = np.abs(x) if floor is None else np.maximum(np.abs(x), floor)
    h = DIFF_STEP * sign * magnitude
    h = np.where((x + h) - x == 0.0, ZERO_STEP * sign * np.maximum(1.0, np.abs(x)), h)
    below, above = x - lo, hi - x
    outside = (x + h < lo) | (x + h > hi)
    fits = np.abs(h) <= np.maximum(below, above)
    h = np.where(outside & fits, -h, h)
    h = np.where(~fits & (above >= below), above, h)
    h = np.where(~fits & (above < below), -below, h)
    columns = []
    for i in range(x.size):
        shifted = x.copy()
        shifted[i] += h[i]
        columns.append((fun(shifted) - f0) / (shifted[i] - x[i]))
    return np.column_stack(columns)


class _FinalJacobian:
    """The fits' Jacobian, skipping the one least squares computes only to stop.

    scipy's trust-region loop computes the Jacobian after every accepted step, even one
    that meets the tolerances and ends the fit: ``n`` simulations for nothing. A step that
    meets them (by the test scipy applies, given a good agreement with its model, which a
    converging fit has) gets the previous Jacobian back instead. Should the loop go on after
    all, it steps once with that Jacobian (a quasi-Newton step) and then with fresh ones.

    Args:
        fun: The residuals, as least squares evaluates them.
        lo: Lower bounds.
        hi: Upper bounds.
        floor: See :func:`forward_jacobian`.
        column: The residuals at a finite-difference step (the same function, its
            simulations started differently).
    """

    def __init__(
        self,
        fun: Callable[[np.ndarray], np.ndarray],
        lo: np.ndarray,
        hi: np.ndarray,
        floor: np.ndarray,
        column: Callable[[np.ndarray], np.ndarray],
    ):
        self._fun = fun
        self._column = column
        self._lo, self._hi = lo, hi
        self._floor = floor
        self._x: np.ndarray | None = None
        self._cost = math.inf
        self._jacobian: np.ndarray | None = None

    def __call__(self, x: np.ndarray) -> np.ndarray:
        f0 = self._fun(x)  # just evaluated by the least squares: remembered, not simulated
        cost = 0.5 * float(f0 @ f0)
        if self._jacobian is not None and self._x is not None and self._stops(x, cost):
            self._x, self._cost = x.copy(), cost
            return self._jacobian
        self._jacobian = forward_jacobian(self._column, x, f0, self._lo, self._hi, self._floor)
        self._x, self._cost = x.copy(), cost
        return self._jacobian

    def _stops(self, x: np.ndarray, cost: float) -> bool:
        assert self._x is not None
        reduction = self._cost - cost
        small = 0.0 < reduction < FIT_FTOL * self._cost
        step = float(np.linalg.norm(x - self._x))
        return small or step < FIT_XTOL * (FIT_XTOL + float(np.linalg.norm(self._x)))
