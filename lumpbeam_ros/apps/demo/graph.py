"""A live ROS 2 graph of child processes: an isolated domain, one log per child, no leftovers.

Each child runs in its own process group (``start_new_session``), so a signal reaches the
child and anything it started, and :meth:`ProcessGraph.close` (run on any exit of the
``with`` block, errors included) interrupts what is still running and kills what does not
stop. Every child gets the same private ``ROS_DOMAIN_ID`` and localhost-only discovery, so a
demo never talks to, or hears, another ROS graph on the machine.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import IO

from lumpbeam_ros.base.closing import ClosedOnExit
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.resources import large_frames_profile
from lumpbeam_ros.nodes.launch_file import NodeLaunch
from lumpbeam_ros.nodes.ros_domain import PRIVATE_DOMAIN_IDS, claim_domain_id

#: The domains a graph may use (see :mod:`lumpbeam_ros.nodes.ros_domain`).
DOMAIN_IDS = PRIVATE_DOMAIN_IDS
#: How long an interrupted child may take to stop before it is killed, s.
STOP_GRACE_S = 10.0
#: Longest a probe waits to discover a publisher before taking it as gone, s.
DISCOVERY_ALLOWANCE_S = 10.0
#: Lines of a failed child's log quoted in the error.
LOG_TAIL_LINES = 5


def python_command(module: str, *args: str) -> list[str]:
    """The command that runs ``python -m module args`` with this interpreter."""
    return [sys.executable, '-m', module, *args]


def script_command(script: str, *args: str) -> list[str]:
    """The command that runs a node's console script (``identifier_node``) with this interpreter.

    Through :mod:`lumpbeam_ros.nodes.scripts`: the signal handlers come before the node's
    imports, so stopping the graph early stops a node that is still starting.
    """
    code = f'import sys; from lumpbeam_ros.nodes.scripts import {script}; sys.exit({script}())'
    return [sys.executable, '-c', code, *args]


def node_command(module: str, *ros_args: str) -> list[str]:
    """The command that runs a node's module as its console script, with ``--ros-args``."""
    return script_command(module.rpartition('.')[2], '--ros-args', *ros_args)


def launched_command(node: NodeLaunch, *ros_args: str) -> list[str]:
    """The command that starts a launch file's node, with more ``--ros-args`` after its own."""
    return script_command(
        node.executable, *replace(node, ros_args=(*node.ros_args, *ros_args)).argv()
    )


@dataclass
class Child:
    """One child process.

    Attributes:
        name: Short name (also the log file's stem).
        argv: Its command line.
        log_path: Where its stdout and stderr go.
        process: The running process.
    """

    name: str
    argv: list[str]
    log_path: Path
    process: subprocess.Popen[bytes]
    _log: IO[bytes]

    def running(self) -> bool:
        """Whether the process has not exited yet."""
        return self.process.poll() is None

    def log_tail(self, lines: int = LOG_TAIL_LINES) -> str:
        """The last lines of its log, joined with `` | `` (for a one-line error)."""
        self._log.flush()
        text = self.log_path.read_text(encoding='utf-8', errors='replace').strip()
        return ' | '.join(text.splitlines()[-lines:]) or '(empty log)'


class ProcessGraph(ClosedOnExit):
    """Starts, watches and stops the processes of one ROS graph.

    Use it as a context manager: leaving the block stops every child still running.

    Args:
        log_dir: Folder for the children's logs (created).
        domain_id: ROS domain; when ``None``, one that no other lumpbeam process holds,
            claimed until :meth:`close` (:func:`~lumpbeam_ros.nodes.ros_domain.claim_domain_id`).
        ros_home: ``ROS_HOME`` (and ``ROS_LOG_DIR`` under it) of the children; ``log_dir``'s
            ``ros`` subfolder when ``None``.
    """

    def __init__(self, log_dir: Path, domain_id: int | None = None, ros_home: Path | None = None):
        self.log_dir = Path(log_dir)
        self.log_dir.mkdir(parents=True, exist_ok=True)
        self._claim = claim_domain_id(DOMAIN_IDS) if domain_id is None else None
        self.domain_id = self._claim.domain_id if self._claim else int(domain_id)
        home = ros_home or self.log_dir / 'ros'
        self.env = dict(os.environ)
        self.env.update(
            ROS_DOMAIN_ID=str(self.domain_id),
            ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
            ROS_HOME=str(home),
            ROS_LOG_DIR=str(home / 'log'),
            PYTHONUNBUFFERED='1',  # logs as they happen, not when a buffer fills
            # Camera frames cross between processes: give shared memory room for them.
            FASTRTPS_DEFAULT_PROFILES_FILE=str(large_frames_profile()),
        )
        self.children: dict[str, Child] = {}

    def start(self, name: str, argv: Sequence[str]) -> Child:
        """Starts a child in its own process group, logging to ``log_dir/<name>.log``.

        Raises:
            LumpbeamError: ``name`` is taken, or the program cannot be started.
        """
        if name in self.children:
            raise LumpbeamError(f'a child named {name!r} is already running')
        log_path = self.log_dir / f'{name}.log'
        log = log_path.open('wb')
        try:
            process = subprocess.Popen(
                list(argv),
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=subprocess.STDOUT,
                env=self.env,
                start_new_session=True,
            )
        except OSError as exc:
            log.close()
            raise LumpbeamError(f'cannot start {name} ({argv[0]}): {exc.strerror}') from None
        child = Child(name, list(argv), log_path, process, log)
        self.children[name] = child
        return child

    def check_running(self, names: Sequence[str] | None = None) -> None:
        """Raises if a child (of ``names``, default all) has exited.

        Raises:
            LumpbeamError: Naming the child, its exit code and the end of its log.
        """
        for name in list(self.children) if names is None else names:
            child = self.children[name]
            code = child.process.poll()
            if code is not None:
                raise LumpbeamError(
                    f'{name} exited early with code {code}: {child.log_tail()} '
                    f'(log: {child.log_path})'
                )

    def wait(self, name: str, timeout_s: float, watch: Sequence[str] = ()) -> int:
        """Waits for a child to exit by itself.

        Args:
            name: The child.
            timeout_s: Longest wait, s.
            watch: Other children that must keep running meanwhile.

        Returns:
            Its exit code (0).

        Raises:
            LumpbeamError: It did not exit in time, exited with an error, or a watched child
                stopped.
        """
        child = self.children[name]
        deadline = time.monotonic() + timeout_s
        while child.running():
            if time.monotonic() > deadline:
                raise LumpbeamError(f'{name} did not finish within {timeout_s:g} s')
            self.check_running(watch)
            time.sleep(0.05)
        return self._exit_code(child)

    def interrupt(self, name: str, grace_s: float = STOP_GRACE_S) -> int:
        """Stops a child as Ctrl-C would (SIGINT to its group), killing it after ``grace_s``.

        Returns:
            Its exit code.

        Raises:
            LumpbeamError: It had to be killed, or exited with an error.
        """
        child = self.children[name]
        if child.running():
            _signal_group(child.process, signal.SIGINT)
            try:
                child.process.wait(grace_s)
            except subprocess.TimeoutExpired:
                _signal_group(child.process, signal.SIGKILL)
                child.process.wait()
                raise LumpbeamError(
                    f'{name} did not stop within {grace_s:g} s of SIGINT; killed'
                ) from None
        return self._exit_code(child)

    def close(self) -> None:
        """Interrupts every child still running, then kills those that do not stop."""
        running = [c for c in self.children.values() if c.running()]
        for child in running:
            _signal_group(child.process, signal.SIGINT)
        deadline = time.monotonic() + STOP_GRACE_S
        for child in running:
            try:
                child.process.wait(max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                _signal_group(child.process, signal.SIGKILL)
                child.process.wait()
        for child in self.children.values():
            child._log.close()
        if self._claim is not None:
            self._claim.release()

    @staticmethod
    def _exit_code(child: Child) -> int:
        code = int(child.process.returncode)
        if code != 0:
            raise LumpbeamError(
                f'{child.name} failed with code {code}: {child.log_tail()} (log: {child.log_path})'
            )
        return code


def _signal_group(process: subprocess.Popen[bytes], sig: int) -> None:
    try:
        os.killpg(process.pid, sig)  # the child leads its own session and group
    except ProcessLookupError:
        pass  # already gone


def wait_for_graph(
    graph: ProcessGraph,
    nodes: Sequence[str] = (),
    subscribers: Mapping[str, int] | None = None,
    timeout_s: float = 30.0,
    announce: Mapping[str, str] | None = None,
) -> None:
    """Waits until the graph's children have joined: named nodes exist, topics have readers.

    Joins the graph's domain with a short-lived probe node of its own (private rclpy
    context). The probe can also subscribe to topics first (``announce``): a recorder that
    subscribes to topics as they appear in the graph then subscribes to them now, before
    their publisher starts, instead of after discovering it (which can take seconds).

    Args:
        graph: The graph (its domain and children).
        nodes: Node names that must be present.
        subscribers: Minimum subscriber count per topic, the probe's own included.
        timeout_s: Longest wait, s.
        announce: Topics the probe subscribes to while waiting, with their types
            (``'pkg/msg/Name'``).

    Raises:
        LumpbeamError: Not ready in time (naming what is missing), or a child exited.
    """
    import rclpy
    from rclpy.context import Context
    from rclpy.node import Node

    from lumpbeam_ros.nodes.msgtypes import message_class

    subscribers = dict(subscribers or {})
    context = Context()
    rclpy.init(context=context, domain_id=graph.domain_id)
    try:
        probe = Node('lumpbeam_demo_probe', context=context)
        for topic, msgtype in (announce or {}).items():
            probe.create_subscription(message_class(msgtype), topic, lambda _msg: None, 10)
        deadline = time.monotonic() + timeout_s
        while True:
            graph.check_running()
            present = set(probe.get_node_names())
            missing = [f'node {n}' for n in nodes if n not in present]
            missing += [
                f'{count} subscriber(s) of {topic}'
                for topic, count in subscribers.items()
                if probe.count_subscribers(topic) < count
            ]
            if not missing:
                break
            if time.monotonic() > deadline:
                raise LumpbeamError(
                    f'the ROS graph was not ready within {timeout_s:g} s: missing '
                    + ', '.join(missing)
                )
            time.sleep(0.1)
        probe.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)


def wait_for_quiet(
    graph: ProcessGraph,
    topics: Mapping[str, str],
    quiet_s: float = 1.0,
    timeout_s: float = 30.0,
) -> dict[str, int]:
    """Waits until no message has arrived on any of ``topics`` for ``quiet_s``.

    After the input of a graph has ended, its nodes may still be working through their
    queues (a camera node a few frames behind on a busy core); stopping the recorder before
    they are done would cut their last messages off. A probe node subscribes to the topics
    (with the project's QoS) and listens until they fall silent; the silence is counted from
    the moment it has discovered a publisher on every topic (or after
    :data:`DISCOVERY_ALLOWANCE_S`, when one has gone).

    Args:
        graph: The graph (its domain).
        topics: Topic names and their types (``'pkg/msg/Name'``), each with a publisher.
        quiet_s: Silence that counts as done, s.
        timeout_s: Longest wait, s; the graph is taken as done then too.

    Returns:
        Messages the probe heard per topic while waiting.
    """
    import rclpy
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node

    from lumpbeam_ros.nodes.msgtypes import message_class, topic_qos

    heard = dict.fromkeys(topics, 0)
    last = {'at': time.monotonic()}

    def on_message(_data: bytes, topic: str) -> None:
        heard[topic] += 1
        last['at'] = time.monotonic()

    context = Context()
    rclpy.init(context=context, domain_id=graph.domain_id)
    try:
        probe = Node('lumpbeam_demo_quiet_probe', context=context)
        for topic, msgtype in topics.items():
            probe.create_subscription(
                message_class(msgtype),
                topic,
                lambda data, topic=topic: on_message(data, topic),
                topic_qos(topic, msgtype),
                raw=True,
            )
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(probe)
        started = time.monotonic()
        deadline = started + timeout_s
        discovered = False
        while time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.05)
            if not discovered:
                discovered = all(probe.count_publishers(t) > 0 for t in topics)
                discovered |= time.monotonic() - started > DISCOVERY_ALLOWANCE_S
                last['at'] = time.monotonic()
            elif time.monotonic() - last['at'] >= quiet_s:
                break
        probe.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)
    return heard
