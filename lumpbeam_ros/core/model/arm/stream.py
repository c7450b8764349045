"""An arm simulated as time passes, following joint commands (the simulator node's arm mode).

:class:`ArmStream` is the ROS-free core of the simulator node for an arm: the node hands it
each ``/joint_trajectory`` command (joint names, times from the command's start, positions)
and the time, and it returns the arm's samples whose stamps fell due since the last call, on
the grid ``k / rate_hz`` as :class:`~lumpbeam_ros.core.model.stream.PredictionStream` does for the
beam.

The joints follow the concatenation of the commands received since the stream's *anchor*,
holding each command's last point until the next one starts; the arm is at rest in its
static equilibrium at the anchor. Each accepted command re-simulates that whole history
with :func:`~lumpbeam_ros.core.model.arm.simulate.simulate_arm` (a command that arrives while the
arm still rings from the previous one inherits that vibration) up to ``ring_down_s`` after its
end; the span is extended the same way when the clock nears its end. The history is bounded:
once the anchor lies more than ``history_s`` behind, the next command or extension moves it
to the present and the arm restarts at rest at the held angles (what vibration is left after
that long is dropped). The first command sets the angles the arm starts from: before it the
joints' angles are unknown and nothing is produced.

A command names every joint once (any order), its times from start increase strictly, its
positions are finite, and its first point at time 0 (if any) is where the joints are: a
servo cannot jump. Anything else is refused with a :class:`~lumpbeam_ros.base.errors.LumpbeamError`
naming the problem, and the stream is left as it was.

The history is kept in seconds from an *origin* (the anchor when the history restarts), not
in the clock's seconds: a stamp of today's clock (1.8e9 s) carries only 2.4e-7 s of
resolution, and 1 kHz samples moved onto it step by jittering intervals whose rates, splined,
shook a shaped move's tip by 0.7 mm.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.drive import SampledMotion
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory, default_joint_names
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.simulate import ArmMotion, simulate_arm

#: Slack when rounding a time to the stamp grid, in grid periods.
_GRID_SLACK = 1e-6
#: A command's first point at time 0 may differ from the held angles by this much, rad.
JUMP_TOLERANCE_RAD = 1e-6


class ArmStream:
    """The arm's samples, produced in step with an outside clock as commands arrive.

    Args:
        model: The arm.
        rate_hz: Output rate, Hz: samples are stamped ``k / rate_hz``.
        ring_down_s: How far past a command's end each simulation reaches, s.
        history_s: The longest history re-simulated, s (see the module's text).

    Raises:
        LumpbeamError: A rate, ring-down or history that is not a positive number.
    """

    def __init__(
        self, model: ArmModel, rate_hz: float, ring_down_s: float = 10.0, history_s: float = 60.0
    ):
        for name, value in (
            ('rate', rate_hz),
            ('ring-down', ring_down_s),
            ('history', history_s),
        ):
            if not math.isfinite(value) or value <= 0.0:
                raise LumpbeamError(f'arm stream: the {name} must be positive, got {value!r}')
        self.model = model
        self.joint_names = default_joint_names(model.n_joints)
        self.rate_hz = float(rate_hz)
        self.ring_down_s = float(ring_down_s)
        self.history_s = float(history_s)
        self._origin = 0.0  # the clock's time of the history's time 0
        self._times: np.ndarray | None = None  # the history's rows since the anchor
        self._angles: np.ndarray | None = None
        self._motion: ArmMotion | None = None  # anchor first, then grid stamps
        self._clock_motion: ArmMotion | None = None  # the same at the clock's times
        self._last_k: int | None = None  # the last grid index produced
        self._first_k = 0  # the grid index of the simulation's first stamp
        self._offset = 0  # 1 when the anchor (the simulation's first time) is off the grid

    @property
    def started(self) -> bool:
        """Whether a command has set the joints' angles."""
        return self._times is not None

    @property
    def anchor_s(self) -> float:
        """When the arm was last at rest (the history's start), s; NaN before a command."""
        return math.nan if self._times is None else self._origin + float(self._times[0])

    @property
    def motion(self) -> ArmMotion | None:
        """The current simulation: the anchor, then the grid stamps up to its end."""
        return self._clock_motion

    def held_angles(self, t: float) -> np.ndarray:
        """The commanded joint angles at ``t`` (the last ones after the history's end).

        Raises:
            LumpbeamError: No command yet.
        """
        if self._times is None or self._angles is None:
            raise LumpbeamError('arm stream: no command yet')
        return self._held_at(t - self._origin)

    def _held_at(self, t: float) -> np.ndarray:
        """:meth:`held_angles` at ``t`` in the history's seconds."""
        assert self._times is not None and self._angles is not None
        return np.array([np.interp(t, self._times, a) for a in self._angles.T])

    def command(
        self,
        names: Sequence[str],
        times_s: Sequence[float],
        positions: np.ndarray,
        start_s: float,
    ) -> JointTrajectory:
        """Takes a command: the joints follow it from ``start_s``.

        Args:
            names: The command's joint names (every joint of the arm once, any order).
            times_s: Each point's time from the command's start, s.
            positions: Angles, rad, (points, joints) in the order of ``names``.
            start_s: When the command starts, s (at or after the last sample produced).

        Returns:
            The command as the joints follow it (the arm's joint order, absolute times).

        Raises:
            LumpbeamError: Unknown or missing joint names, the wrong number of positions,
                no point, NaN, times that do not increase, a start before the last sample
                produced, a command longer than ``history_s`` or starting more than that after
                the last sample, a position outside a joint's ``joint_limits_rad``, a jump at
                time 0, or a simulation that failed; the stream is then unchanged.
        """
        command = self._checked(names, times_s, positions, start_s)
        origin = start_s if self._times is None else self._origin
        start = start_s - origin  # in the history's seconds: the command's rows keep their own
        times, angles = start + command.time_s, command.angles_rad
        if self._times is not None and self._angles is not None:
            held = self._held_at(start)
            if times[0] == start and np.max(np.abs(angles[0] - held)) > JUMP_TOLERANCE_RAD:
                raise LumpbeamError(
                    f'the first point at time 0 is {np.max(np.abs(angles[0] - held)):.3g} rad '
                    'from where the joints are: a servo cannot jump (start it at a later time)'
                )
            anchor = float(self._times[0])
            if start - anchor > self.history_s:
                # Re-anchored at rest at the held angles, from the next stamp due.
                anchor = start
                if self._last_k is not None:
                    anchor = min(start, max(anchor, (self._last_k + 1) / self.rate_hz - origin))
            keep = (self._times > anchor) & (self._times < start)
            head_t = np.concatenate([[anchor], self._times[keep], [start]])
            head_q = np.vstack([self._held_at(anchor), self._angles[keep], held])
            if times[0] == start or anchor == start:
                head_t, head_q = head_t[:-1], head_q[:-1]
            times = np.concatenate([head_t, times])
            angles = np.vstack([head_q, angles])
        elif times[0] > start:  # the first command: the arm at rest at its first point
            times = np.concatenate([[start], times])
            angles = np.vstack([angles[:1], angles])
        self._simulate(times, angles, float(times[-1]) + self.ring_down_s, origin)
        return JointTrajectory(start_s + command.time_s, command.angles_rad, self.joint_names)

    def _checked(
        self, names: Sequence[str], times_s: Sequence[float], positions: np.ndarray, start_s: float
    ) -> JointTrajectory:
        """The command in the arm's joint order, its times from its start, or why not."""
        names = list(names)
        unknown = [n for n in names if n not in self.joint_names]
        if unknown:
            raise LumpbeamError(
                f'unknown joint name(s) {unknown}: the arm has {list(self.joint_names)}'
            )
        if len(names) != self.model.n_joints or len(set(names)) != len(names):
            raise LumpbeamError(
                f'{len(names)} joint name(s) {names}: the arm has {self.model.n_joints} joints, '
                'each to be named once'
            )
        times = np.asarray(times_s, dtype=float)
        positions = np.asarray(positions, dtype=float)
        if times.ndim != 1 or times.size == 0:
            raise LumpbeamError('no point')
        if positions.shape != (times.size, len(names)):
            raise LumpbeamError(
                f'{positions.shape} positions for {times.size} points of {len(names)} joints'
            )
        if not (np.all(np.isfinite(times)) and np.all(np.isfinite(positions))):
            raise LumpbeamError('times and positions must be finite numbers')
        if times[0] < 0.0 or np.any(np.diff(times) <= 0.0):
            raise LumpbeamError('point times must start at 0 or later and increase strictly')
        if not math.isfinite(start_s):
            raise LumpbeamError(f'start time {start_s!r} is not finite')
        if self._last_k is not None and start_s < self._last_k / self.rate_hz:
            raise LumpbeamError(
                f'starts at {start_s:.3f} s, before the last sample predicted '
                f'({self._last_k / self.rate_hz:.3f} s)'
            )
        if times[-1] > self.history_s:
            raise LumpbeamError(
                f'lasts {times[-1]:.6g} s, longer than the history simulated '
                f'({self.history_s:g} s)'
            )
        if self._last_k is not None and start_s - self._last_k / self.rate_hz > self.history_s:
            raise LumpbeamError(
                f'starts {start_s - self._last_k / self.rate_hz:.6g} s after the last sample, '
                f'more than the history simulated ({self.history_s:g} s)'
            )
        order = [names.index(n) for n in self.joint_names]
        self.model.config.check_within_limits(positions[:, order], 'the command')
        if times.size == 1:
            return JointTrajectory(
                np.array([times[0], times[0] + 1.0]), positions[[0, 0]][:, order]
            )
        return JointTrajectory(times, positions[:, order], self.joint_names)

    def _simulate(self, times: np.ndarray, angles: np.ndarray, end: float, origin: float) -> None:
        """Simulates the history from its anchor to ``end`` and keeps it on success.

        Args:
            times: The history's rows, s from ``origin``; the first is the anchor.
            angles: Their angles, rad.
            end: Where the simulation ends, s from ``origin``.
            origin: The clock's time of the times' 0, s.
        """
        if times.size == 1:
            times, angles = np.append(times, times[0] + 1.0), np.vstack([angles, angles])
        # Kept from the anchor on: the history's seconds stay small.
        anchor = origin + float(times[0])
        history = JointTrajectory(times - times[0], angles, self.joint_names)
        end -= float(times[0])
        first = math.ceil(anchor * self.rate_hz - _GRID_SLACK)
        last = math.floor((anchor + end) * self.rate_hz + _GRID_SLACK)
        # The grid in the history's seconds: one rounding of the clock's, then exact steps.
        lead = first / self.rate_hz - anchor
        # The anchor is the first output time (the arm at rest there); an anchor between two
        # stamps is simulated but never produced.
        on_grid = abs(lead) * self.rate_hz < _GRID_SLACK
        grid = (0.0 if on_grid else lead) + np.arange(last - first + 1) / self.rate_hz
        t_eval = np.concatenate([[0.0], grid[1:] if on_grid else grid])
        motion = simulate_arm(self.model, SampledMotion(history), t_eval)
        if not (np.all(np.isfinite(motion.phi)) and np.all(np.isfinite(motion.tip_z))):
            raise LumpbeamError('the simulation gave non-finite angles')
        self._origin = anchor
        self._times, self._angles, self._motion = history.time_s, history.angles_rad, motion
        self._clock_motion = replace(motion, t=anchor + motion.t)
        self._first_k, self._offset = first, 0 if on_grid else 1

    def advance_to(self, now: float) -> ArmMotion:
        """The samples stamped after the last call's and at or before ``now``.

        The first call after the first command starts at the first grid stamp at or after
        the anchor. A clock that goes back produces nothing until it passes the last stamp.

        Raises:
            LumpbeamError: Extending the simulation failed (the last span stays).
        """
        motion = self._motion
        if motion is None:
            return _empty(self.model)
        newest = math.floor(now * self.rate_hz + _GRID_SLACK)
        if newest / self.rate_hz > self._origin + float(motion.t[-1]) - 1.0 / self.rate_hz:
            self._extend(now)
            motion = self._motion
            assert motion is not None
        keys = self._first_k + np.arange(motion.t.size - self._offset)
        wanted = keys <= newest
        if self._last_k is not None:
            wanted &= keys > self._last_k
        index = np.flatnonzero(wanted) + self._offset
        if index.size == 0:
            return _empty(self.model)
        self._last_k = int(keys[index[-1] - self._offset])
        return ArmMotion(
            keys[index - self._offset] / self.rate_hz,  # the stamps, on the clock's grid
            motion.q[index],
            motion.phi[index],
            motion.phi_dot[index],
            motion.tip_x[index],
            motion.tip_z[index],
            motion.tip_pitch[index],
        )

    def _extend(self, now: float) -> None:
        """Simulates further (or re-anchors at rest) so the span reaches past ``now``."""
        assert self._times is not None and self._angles is not None
        end = now + self.ring_down_s
        if now - self.anchor_s > self.history_s and now >= self._origin + float(self._times[-1]):
            # At rest from the next stamp on: no stamp is skipped.
            start = now if self._last_k is None else (self._last_k + 1) / self.rate_hz
            held = self.held_angles(start)[None, :]
            self._simulate(np.zeros(1), held, end - start, start)
        else:
            self._simulate(self._times, self._angles, end - self._origin, self._origin)

    def restart_at(self, t: float) -> None:
        """Restarts at rest at ``t`` with the joints held where they are (a clock that jumped).

        The commands since the anchor are forgotten and the next sample is the first stamp
        at or after ``t``. Before any command, nothing changes.

        Raises:
            LumpbeamError: The simulation failed (the stream is then unchanged).
        """
        if self._times is None:
            return
        held = self.held_angles(t)
        self._simulate(np.zeros(1), held[None, :], self.ring_down_s, t)
        self._last_k = None


def _empty(model: ArmModel) -> ArmMotion:
    n, j = model.chain.n, model.n_joints
    return ArmMotion(
        np.empty(0), np.empty((0, j)), np.empty((0, n)), np.empty((0, n)), *np.empty((3, 0))
    )
