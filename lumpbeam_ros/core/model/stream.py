"""A beam simulated as time passes, producing tip poses on a fixed stamp grid (the live node).

:class:`PredictionStream` is the ROS-free core of the simulator node: the node tells it the
time (its clock) and the load changes (``/tip_load``), and it returns the tip poses whose
stamps fell due since the last call. Stamps lie on the grid ``k / rate_hz`` (so a 180 Hz
prediction shares its stamps with a 180 Hz camera that started on a whole second) and each
sample is computed at its own stamp, however late the call comes.

Load changes are queued with their time and applied when the simulation reaches it, so a
change that arrives between two ticks still takes effect at its own instant. One that arrives
after the simulation passed its instant (a message delayed on a loaded machine) is simulated
again from the last checkpoint before it, up to :data:`REWIND_S` back: the samples already
returned stay as they were, the later ones follow the load from its own instant rather than
carry the delay through the whole ring-down. The sensor
effects are applied as in :func:`~lumpbeam_ros.core.model.simulate.simulate_loads`: the sample
stamped ``t`` shows the beam at ``t - latency``, which is what a late camera would report, and
its position's displacement from rest is ``sensor_scale`` times the true one.
"""

from __future__ import annotations

import bisect
import copy
import math

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import POSE_RATE_HZ
from lumpbeam_ros.core.model.integrate import ChainState
from lumpbeam_ros.core.model.parameters import BeamParameters
from lumpbeam_ros.core.model.sensor import measured_position, scaled_position
from lumpbeam_ros.core.model.simulate import DEFAULT_STEP_S, BeamSimulation
from lumpbeam_ros.core.model.trajectory import TipTrajectory

#: Slack when rounding a time to the stamp grid, in grid periods: a clock that reads 1 ns
#: short of a stamp because of float rounding still produces that stamp.
_GRID_SLACK = 1e-6

#: How far back a late load change is simulated again, s: far beyond a message's delivery
#: delay on a loaded machine, and a bounded memory (one checkpoint per call).
REWIND_S = 1.0


def _check_load(load_kg: float) -> float:
    if not math.isfinite(load_kg) or load_kg < 0.0:
        raise ValueError(f'tip load must be a non-negative number of kg, got {load_kg!r}')
    return float(load_kg)


class PredictionStream:
    """Tip poses of a simulated beam, produced in step with an outside clock.

    Args:
        beam: The beam.
        load_kg: The load hanging at the tip at ``t0``; the beam starts at rest in its
            static equilibrium for it.
        t0: Start time, s (any epoch: wall time or a bag's time).
        rate_hz: Output rate, Hz: samples are stamped ``k / rate_hz``.
        step: Internal grid spacing of the simulation, s.

    Raises:
        ValueError: A negative or non-finite load, or a non-positive rate.
    """

    def __init__(
        self,
        beam: BeamParameters,
        load_kg: float,
        t0: float,
        rate_hz: float = POSE_RATE_HZ,
        step: float = DEFAULT_STEP_S,
    ):
        self.step = step
        self._beam = beam
        self._rate_hz = 0.0
        self._time: float  # set by reset(), which ends this constructor
        self.rate_hz = rate_hz
        self._events: list[tuple[float, float]] = []
        # The simulation as each call found it, and every change queued since the oldest.
        self._checkpoints: list[BeamSimulation] = []
        self._log: list[tuple[float, float]] = []
        self.reset(t0, load_kg)

    @property
    def beam(self) -> BeamParameters:
        """The beam being simulated."""
        return self._beam

    @property
    def rate_hz(self) -> float:
        """Output rate, Hz."""
        return self._rate_hz

    @rate_hz.setter
    def rate_hz(self, value: float) -> None:
        if not math.isfinite(value) or value <= 0.0:
            raise ValueError(f'output rate must be a positive number of Hz, got {value!r}')
        # Keep the next stamp on or after the last one produced when the grid changes.
        if self._rate_hz > 0.0:
            self._next_index = math.floor(self.time * value + _GRID_SLACK) + 1
        self._rate_hz = float(value)

    @property
    def time(self) -> float:
        """The latest time the stream was advanced to (or reset at), s."""
        return self._time

    @property
    def load_kg(self) -> float:
        """The load at the tip after every queued change, kg."""
        return self._events[-1][1] if self._events else self._simulation.load_kg

    def reset(self, t: float, load_kg: float | None = None) -> None:
        """Restarts at rest in the static equilibrium, forgetting the motion and queued loads.

        Args:
            t: The new start time, s; the first sample is the first stamp at or after it that
                was not produced yet (all of them again when ``t`` is before :attr:`time`).
            load_kg: The load from now on; ``None`` keeps the current one (queued changes
                included).

        Raises:
            ValueError: A negative or non-finite load.
        """
        load = _check_load(self.load_kg if load_kg is None else load_kg)
        first_index = math.ceil(t * self._rate_hz - _GRID_SLACK)
        if hasattr(self, '_time') and t >= self._time:
            first_index = max(first_index, self._next_index)  # never a stamp twice
        # The grid slack may put the first stamp a hair before t: start the (resting) beam
        # there, so that its first sample is not in its past.
        start = min(t, first_index / self._rate_hz) - self._beam.effects.latency_s
        self._simulation = BeamSimulation(self._beam, load, t0=start, step=self.step)
        self._events.clear()
        self._forget_past()
        self._time = float(t)
        self._origin = float(t)  # mount_creep counts from here
        self._next_index = first_index

    def set_beam(self, beam: BeamParameters) -> None:
        """Swaps the beam's parameters, keeping the motion (angles, rates, load, time).

        A longer ``sensor_latency`` holds the pose for the difference (the samples then
        show the motion that much later, as a later camera would); a shorter one skips it.

        Args:
            beam: The new beam, with the same number of segments.

        Raises:
            ValueError: ``beam`` has another number of segments (its state would not fit).
        """
        if beam.n_segments != self._beam.n_segments:
            raise ValueError(
                f'cannot keep the motion of {self._beam.n_segments} segments in a beam of '
                f'{beam.n_segments}'
            )
        old = self._simulation
        simulation = BeamSimulation(beam, old.load_kg, t0=old.time, step=self.step)
        simulation.state = ChainState(old.state.phi.copy(), old.state.phi_dot.copy())
        self._beam, self._simulation = beam, simulation
        self._forget_past()  # a rewind would simulate the past with the new beam

    def _forget_past(self) -> None:
        self._checkpoints.clear()
        self._log.clear()

    def set_load(self, t: float, load_kg: float) -> None:
        """Queues a load change at time ``t`` (a drop is a change to a smaller load).

        A change dated before the simulation's present (a late message) is simulated again
        from the last checkpoint at or before ``t`` (the oldest one when ``t`` is older than
        them all, or the present when there is none: just after a reset or a new beam).

        Args:
            t: When the load changed, s.
            load_kg: The load from then on, kg.

        Raises:
            ValueError: A negative or non-finite load or time.
        """
        load = _check_load(load_kg)
        if not math.isfinite(t):
            raise ValueError(f'load change time must be finite, got {t!r}')
        event = (float(t), load)
        if t < self._simulation.time and self._checkpoints:
            self._rewind(t)
        bisect.insort(self._events, event, key=lambda queued: queued[0])
        bisect.insort(self._log, event, key=lambda queued: queued[0])

    def _rewind(self, t: float) -> None:
        """Goes back to the last checkpoint at or before ``t``, its later changes queued again."""
        times = [checkpoint.time for checkpoint in self._checkpoints]
        index = max(bisect.bisect_right(times, t) - 1, 0)
        checkpoint = self._checkpoints[index]
        del self._checkpoints[index + 1 :]
        # Restored as a copy: the checkpoint may be needed again by a later, later message.
        self._simulation = copy.copy(checkpoint)
        self._events = [event for event in self._log if event[0] > checkpoint.time]

    def equilibrium_pose(self, load_kg: float | None = None) -> tuple[float, float, float]:
        """The tip pose ``(x, z, pitch)`` at rest under a load (default: the current one)."""
        simulation = BeamSimulation(self._beam, self.load_kg if load_kg is None else load_kg)
        x, z, pitch = simulation.chain.tip_pose(simulation.state.phi[None, :])
        x, z = scaled_position(self._beam, x, z)
        return float(x[0]), float(z[0]), float(pitch[0])

    def advance_to(self, now: float) -> TipTrajectory:
        """Advances to ``now`` and returns the samples stamped in ``(previous now, now]``.

        Args:
            now: The clock's time, s; earlier than :attr:`time` gives no samples (the caller
                decides whether a clock going back means :meth:`reset`).

        Returns:
            The due samples (possibly none), each with the load at its instant.

        Raises:
            LumpbeamError: The simulation failed (diverged, or over its solver's budget). The
                stream has then restarted at rest at ``now`` under the current load: left
                behind, every later call would have to simulate from the failure on, longer
                each time (a simulator node once spent minutes on 447 s of it).
        """
        if now <= self._time:
            return _empty()
        self._time = float(now)
        last_index = math.floor(now * self._rate_hz + _GRID_SLACK)
        if last_index < self._next_index:
            return _empty()
        stamps = np.arange(self._next_index, last_index + 1) / self._rate_hz
        self._next_index = last_index + 1
        try:
            return self._simulate(stamps)
        except LumpbeamError:
            self.reset(now)
            raise

    def _simulate(self, stamps: np.ndarray) -> TipTrajectory:
        """The samples at ``stamps``, the simulation advanced through them."""
        self._checkpoint()
        simulation = self._simulation
        # Not before the simulation's present: a latency made longer holds the pose.
        physical = np.maximum(stamps - self._beam.effects.latency_s, simulation.time)
        n = self._beam.n_segments
        phi = np.empty((stamps.size, n))
        loads = np.empty(stamps.size)
        lo = 0
        while self._events and self._events[0][0] <= physical[-1]:
            when, load = self._events.pop(0)
            hi = int(np.searchsorted(physical, when, side='left'))
            if hi > lo:
                phi[lo:hi], _ = simulation.advance(physical[lo:hi])
                loads[lo:hi] = simulation.load_kg
                lo = hi
            if when > simulation.time:
                simulation.advance(np.array([when]))
            simulation.set_load(load)
        phi[lo:], _ = simulation.advance(physical[lo:])
        loads[lo:] = simulation.load_kg
        x, z, pitch = simulation.chain.tip_pose(phi)
        x, z = measured_position(self._beam, stamps - self._origin, x, z)
        return TipTrajectory(t=stamps, x=x, z=z, pitch=pitch, load_kg=loads, q=phi)

    def _checkpoint(self) -> None:
        """Keeps the simulation as it is now, and forgets what is older than a rewind reaches.

        A shallow copy is enough: advancing replaces the simulation's state and time rather
        than change them in place, and its solver caches stay valid for every copy.
        """
        simulation = self._simulation
        self._checkpoints.append(copy.copy(simulation))
        horizon = simulation.time - REWIND_S
        while len(self._checkpoints) > 1 and self._checkpoints[1].time <= horizon:
            del self._checkpoints[0]
        oldest = self._checkpoints[0].time
        while self._log and self._log[0][0] <= oldest:
            del self._log[0]


def _empty() -> TipTrajectory:
    nothing = np.empty(0)
    return TipTrajectory(t=nothing, x=nothing, z=nothing, pitch=nothing, load_kg=nothing)
