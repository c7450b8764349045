"""Simulations of the beam under tip-load events: batch (drop tests) and streaming (the node).

A load change (a drop) changes the masses and with them the equilibrium; the angles and
velocities carry over, since releasing a load leaves the beam's own velocities unchanged.
Each stretch between events is integrated by
:class:`~lumpbeam_ros.core.model.integrate.ModalSolver` (with its Radau fallback), and tip poses at
the requested times are interpolated with cubic Hermite splines of the angles (the solver gives
their rates too).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import POSE_RATE_HZ
from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.hermite import hermite
from lumpbeam_ros.core.model.integrate import ChainState, ModalSolver, solve_reference
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.core.model.sensor import measured_position
from lumpbeam_ros.core.model.statics import static_equilibrium
from lumpbeam_ros.core.model.trajectory import TipTrajectory

#: Internal grid spacing, s. The linear dynamics are propagated exactly whatever the step;
#: it only samples the small nonlinear remainder. At 1/180 s a 10 s drop test agrees with a
#: Radau run at rtol 1e-10 to 0.04 um (``lumpbeam bench`` prints the figure).
DEFAULT_STEP_S = 1.0 / 180.0


class SimulationDivergedError(LumpbeamError):
    """The modal solver cannot integrate a beam and the stiff fallback is off."""


class WarmStart:
    """The converged nonlinear remainders of a simulation, to start a similar one from.

    A fit simulates the same record's stretches for beams that differ by a step of the
    least squares: handed the previous simulation's remainder, each stretch's sweeps start
    next to the fixed point (:meth:`~lumpbeam_ros.core.model.integrate.ModalSolver.solve`), which
    they reach in about half the sweeps. The result is the same to the solver's tolerance.
    Keyed by the stretch's start and load; only a grid of the same shape is used.
    """

    def __init__(self) -> None:
        self._remainders: dict[tuple[float, float], tuple[np.ndarray, float]] = {}

    def get(self, start_s: float, load_kg: float) -> np.ndarray | None:
        """The remainder last stored for a stretch (``None``: none yet)."""
        stored = self._remainders.get((start_s, load_kg))
        return None if stored is None else stored[0]

    def contraction(self, start_s: float, load_kg: float) -> float:
        """The sweeps' contraction that the stretch's last solve showed (NaN: none)."""
        return self._remainders.get((start_s, load_kg), (None, math.nan))[1]

    def put(
        self,
        start_s: float,
        load_kg: float,
        remainder: np.ndarray | None,
        contraction: float = math.nan,
    ) -> None:
        """Stores a stretch's converged remainder and contraction (``None`` is ignored)."""
        if remainder is not None:
            self._remainders[(start_s, load_kg)] = (remainder, contraction)

    def __len__(self) -> int:
        """The number of stretches with a remainder stored."""
        return len(self._remainders)

    def copy(self) -> WarmStart:
        """An independent copy (the arrays are shared: they are never modified)."""
        other = WarmStart()
        other._remainders = dict(self._remainders)
        return other


class BeamSimulation:
    """A beam advanced in time, with the tip load changeable between advances.

    Args:
        beam: The beam.
        load_kg: The load hanging at the tip at the start; the beam starts at rest in its
            static equilibrium for that load.
        t0: Start time, s.
        step: Internal grid spacing, s.
        stiff_fallback: Integrate a stretch the modal solver cannot (extreme parameters) with
            the Radau reference; ``False`` raises :class:`SimulationDivergedError` instead (a fit
            takes such parameters for a bad fit rather than wait minutes for Radau).
        warm: Remainders to start each stretch's sweeps from, updated with this
            simulation's (``None``: every stretch starts from zero).
    """

    def __init__(
        self,
        beam: BeamParameters,
        load_kg: float = 0.0,
        t0: float = 0.0,
        step: float = DEFAULT_STEP_S,
        stiff_fallback: bool = True,
        warm: WarmStart | None = None,
    ):
        self.beam = beam
        self.stiff_fallback = stiff_fallback
        self.warm = warm
        self.step = step
        self.time = float(t0)
        self.load_kg = float(load_kg)
        self._chains: dict[float, LumpedChain] = {}
        self._solvers: dict[float, ModalSolver] = {}
        chain = self._chain(self.load_kg)
        self.state = ChainState(static_equilibrium(chain), np.zeros(beam.n_segments))
        self._rest = (self.state, self.load_kg)

    def _chain(self, load_kg: float) -> LumpedChain:
        if load_kg not in self._chains:
            self._chains[load_kg] = LumpedChain.from_beam(self.beam, load_kg)
        return self._chains[load_kg]

    def _solver(self, load_kg: float) -> ModalSolver:
        # Built only for a load the beam moves under: a drop test never integrates its
        # loaded rest, so it never pays for that configuration's eigen-decomposition.
        if load_kg not in self._solvers:
            self._solvers[load_kg] = ModalSolver(self._chain(load_kg))
        return self._solvers[load_kg]

    @property
    def chain(self) -> LumpedChain:
        """The chain with the current load."""
        return self._chain(self.load_kg)

    def set_load(self, load_kg: float) -> None:
        """Changes the tip load now; the motion carries over.

        Args:
            load_kg: The new load, kg (not negative).

        Raises:
            ValueError: A negative or non-finite load.
        """
        if not np.isfinite(load_kg) or load_kg < 0.0:
            raise ValueError(f'tip load must be a non-negative number of kg, got {load_kg!r}')
        self.load_kg = float(load_kg)

    def advance(self, t_out: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Advances to ``t_out[-1]`` and returns the angles and rates at ``t_out``.

        Args:
            t_out: Increasing times, all at or after the current time.

        Returns:
            Angles and angular velocities, each shape (len(t_out), n).

        Raises:
            ValueError: ``t_out`` is empty, not increasing, or starts before the current time.
        """
        t_out = np.asarray(t_out, dtype=float)
        if t_out.size == 0 or np.any(np.diff(t_out) < 0) or t_out[0] < self.time - 1e-12:
            raise ValueError('output times must be increasing and not before the current time')
        duration = float(t_out[-1] - self.time)
        # Still in the starting rest, with its load: nothing to integrate (a drop test's
        # seconds before the release cost nothing).
        at_rest = self.state is self._rest[0] and self.load_kg == self._rest[1]
        if duration <= 0.0 or at_rest:
            self.time = max(self.time, float(t_out[-1]))
            phi = np.repeat(self.state.phi[None, :], t_out.size, axis=0)
            return phi, np.repeat(self.state.phi_dot[None, :], t_out.size, axis=0)
        solver = self._solver(self.load_kg)
        stretch = (self.time, self.load_kg)
        warm = None if self.warm is None else self.warm.get(*stretch)
        contraction = math.nan if self.warm is None else self.warm.contraction(*stretch)
        solution = solver.solve(
            self.state, duration, self.step, remainder=warm, contraction=contraction
        )
        if self.warm is not None and solution is not None:
            self.warm.put(*stretch, solution.remainder, solution.contraction)
        if solution is None:
            if not self.stiff_fallback:
                raise SimulationDivergedError(
                    f'the modal solver did not converge over {duration:.3f} s: the beam is '
                    'too far from its linearisation (extreme parameters)'
                )
            steps = max(1, int(np.ceil(duration / self.step)))
            grid = np.linspace(0.0, duration, steps + 1)
            solution = solve_reference(solver.chain, self.state, grid)
        grid_t = solution.t + self.time
        self.state = solution.final_state()
        self.time = float(t_out[-1])
        if solution.t.size < 2:
            return solution.phi[-1:].repeat(t_out.size, 0), solution.phi_dot[-1:].repeat(
                t_out.size, 0
            )
        return hermite(grid_t, solution.phi, solution.phi_dot, t_out)


def simulate_loads(
    beam: BeamParameters,
    t: np.ndarray,
    load_events: Sequence[tuple[float, float]],
    initial_load_kg: float = 0.0,
    step: float = DEFAULT_STEP_S,
    stiff_fallback: bool = True,
    warm: WarmStart | None = None,
) -> TipTrajectory:
    """Simulates the tip under a schedule of load changes, starting at rest.

    The sensor effects of ``beam`` are applied to the result: with ``sensor_latency`` the
    sample stamped ``t`` shows the beam at ``t - latency`` (before the start, at rest), with
    ``sensor_scale`` the position's displacement from rest is scaled
    (:func:`~lumpbeam_ros.core.model.sensor.measured_position`), and with ``mount_creep`` z moves
    by the rate times the time since ``t[0]``.

    Args:
        beam: The beam.
        t: Output times, increasing.
        load_events: ``(time, load_kg)`` changes, in any order.
        initial_load_kg: The load before the first event; the beam starts at rest with it.
        step: Internal grid spacing, s.
        stiff_fallback: See :class:`BeamSimulation`.
        warm: See :class:`BeamSimulation`.

    Returns:
        The tip trajectory at ``t``, with the load at each sample.

    Raises:
        SimulationDivergedError: The modal solver failed and ``stiff_fallback`` is off.
    """
    t = np.asarray(t, dtype=float)
    latency = beam.effects.latency_s
    physical_t = t - latency
    events = sorted((float(te), float(kg)) for te, kg in load_events)
    start = min(float(physical_t[0]), events[0][0] if events else np.inf)
    simulation = BeamSimulation(beam, initial_load_kg, start, step, stiff_fallback, warm)
    n = beam.n_segments
    phi = np.empty((t.size, n))
    loads = np.empty(t.size)
    # The start is never after the first event, so every event is a boundary; one at the
    # start itself changes the load of a beam already at rest with the initial load.
    boundaries = [te for te, _ in events] + [np.inf]
    load_after = [kg for _, kg in events]
    lo = 0
    for index, boundary in enumerate(boundaries):
        hi = int(np.searchsorted(physical_t, boundary, side='left'))
        if hi > lo:
            phi[lo:hi], _ = simulation.advance(physical_t[lo:hi])
            loads[lo:hi] = simulation.load_kg
        if np.isfinite(boundary):
            simulation.advance(np.array([boundary]))
            simulation.set_load(load_after[index])
        lo = hi
        if lo >= t.size:
            break
    x, z, pitch = simulation.chain.tip_pose(phi)
    x, z = measured_position(beam, t - t[0] if t.size else t, x, z)
    return TipTrajectory(t=t, x=x, z=z, pitch=pitch, load_kg=loads, q=phi)


def drop_test_events(drop: DropTestConfig) -> list[tuple[float, float]]:
    """The load schedule of a drop test: the load released at ``release_time_s``."""
    return [(drop.release_time_s, 0.0)]


def simulate_drop_test(
    beam: BeamParameters,
    drop: DropTestConfig | None = None,
    rate_hz: float = POSE_RATE_HZ,
    step: float = DEFAULT_STEP_S,
) -> TipTrajectory:
    """The paper's drop test (section B.3): at rest with ``m_d + m_l``, ``m_l`` released.

    The paper raises the damping five-fold before the drop only to settle its simulation;
    here the beam starts exactly at its loaded equilibrium, so no settling is needed.

    Args:
        beam: The beam (``tip_mass_kg`` is m_d).
        drop: The scenario (default: 4.5 kg released at 2 s, 12 s long).
        rate_hz: Output rate, Hz.
        step: Internal grid spacing, s.

    Returns:
        The tip trajectory from 0 to ``duration_s`` at ``rate_hz``.
    """
    drop = DropTestConfig() if drop is None else drop
    count = int(np.floor(drop.duration_s * rate_hz + 1e-9)) + 1
    t = np.arange(count) / rate_hz
    return simulate_loads(beam, t, drop_test_events(drop), drop.load_kg, step)
