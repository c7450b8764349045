"""How every node process runs: init, build the node, spin, count, shut down.

One place for what each node's ``main`` did alike (:func:`run_node`):

* a configuration error while the node is built is one line on stderr and exit code 2 (no
  traceback);
* Ctrl-C, SIGTERM or an external shutdown ends the spin quietly, also when the shutdown cuts
  into a callback that publishes; SIGINT and SIGTERM also interrupt a callback that computes
  (a long solve), so the node stops within a fraction of a second whatever it is doing;
* what the node published is written for the demo's per-topic counts
  (:mod:`lumpbeam_ros.nodes.counts`) however it stopped.

A node fed at camera rate spins with :func:`spin_events` instead of ``rclpy.spin``, or with
:func:`spin_live`, which keeps ``rclpy.spin`` for a node on a simulated clock.

The commands that run a node in their own loop (``lumpbeam play``, ``lumpbeam record``) take
their namespace from :func:`checked_namespace`, their topic names from :func:`checked_topics`
and their rclpy session and stop request from :func:`stoppable_session`.
"""

from __future__ import annotations

import functools
import sys
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from types import FrameType
from typing import Any, TypeVar

import rclpy
from rclpy.exceptions import (
    InvalidNamespaceException,
    InvalidTopicNameException,
    ParameterException,
)
from rclpy.executors import ExternalShutdownException
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from rclpy.validate_full_topic_name import validate_full_topic_name
from rclpy.validate_namespace import validate_namespace
from rclpy.validate_topic_name import validate_topic_name

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interrupts import (
    interrupt_on_signals,
    interrupted,
    record_signal,
    restore_handlers,
)
from lumpbeam_ros.nodes.counts import write_counts

#: Exit code of a node whose configuration is invalid.
CONFIG_ERROR = 2

_N = TypeVar('_N', bound=Node)


def run_node(
    name: str,
    make: Callable[[], _N],
    published: Callable[[_N], Mapping[str, int]],
    args: Sequence[str] | None = None,
    run: Callable[[_N], None] = rclpy.spin,
    received: Callable[[_N], Mapping[str, int]] | None = None,
) -> int:
    """Runs one node process until it is stopped.

    Args:
        name: The node's name, the prefix of its error line and the name of its counts.
        make: Builds the node (after ``rclpy.init``).
        published: Messages published per topic, read when the node stops.
        args: Command-line arguments (default ``sys.argv``), incl. ``--ros-args``.
        run: What to do with the node (default: spin it until shutdown).
        received: Messages received per topic, read when the node stops.

    Returns:
        0 after a clean stop, :data:`CONFIG_ERROR` when the node cannot be built or ``run``
        fails on its configuration.
    """
    # Before rclpy.init: rclpy's handler shuts the context down (which ends a wait) and then
    # calls the handler it found, this one, which interrupts a callback that computes.
    # Without it SIGTERM, and SIGINT in a process started with SIGINT ignored (a background
    # job), only shut the context down, and a callback busy in a long solve runs on.
    argv = list(sys.argv if args is None else args)
    if _wants_help(argv):
        from lumpbeam_ros.nodes.params.reference import help_text

        sys.stdout.write(help_text(name))
        return 0
    problem = params_file_problem(argv)
    if problem is not None:
        print(f'{name}: error: {problem}', file=sys.stderr)
        return CONFIG_ERROR
    previous = interrupt_on_signals()
    built: list[_N] = []
    try:
        return _build_and_run(name, argv, make, run, built)
    except KeyboardInterrupt:
        # rclpy's handler runs first and shuts the context down, which may end the spin; the
        # interrupt then reaches Python only in one of _build_and_run's except clauses.
        return 0
    finally:
        try:
            _finish(name, built, published, received)
        except KeyboardInterrupt:
            # That interrupt may also come at the call itself, before _finish holds it off; a
            # signal raises once, so the second call runs through.
            _finish(name, built, published, received)
        restore_handlers(previous)


def _build_and_run(
    name: str,
    argv: list[str],
    make: Callable[[], _N],
    run: Callable[[_N], None],
    built: list[_N],
) -> int:
    """:func:`run_node`'s init, build and run; the node built is appended to ``built``."""
    try:
        try:
            rclpy.init(args=argv)
        except _rclpy.RCLError as exc:
            print(f'{name}: error: bad --ros-args ({exc})', file=sys.stderr)
            return CONFIG_ERROR
        node = make()
        built.append(node)
        if run in (rclpy.spin, spin_events, spin_live):
            # A node that joins the graph says so once; one that reads a bag through (the
            # camera node given a bag) is a batch job and says what it reads instead.
            node.get_logger().info('ready')
        run(node)
    except (LumpbeamError, ParameterException) as exc:
        print(f'{name}: error: {exc}', file=sys.stderr)
        return CONFIG_ERROR
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except _rclpy.RCLError:
        # rclpy's SIGINT/SIGTERM handler shuts the context down under a running callback,
        # whose next publish then fails: that is the stop, not a fault.
        if rclpy.ok():
            raise
    except RuntimeError:
        # An interrupt raised inside rclpy's C++ (pybind11 converting a call's arguments)
        # comes out as a RuntimeError: after a signal, that is the stop too.
        if not interrupted():
            raise
    return 0


def _finish(
    name: str,
    built: list[_N],
    published: Callable[[_N], Mapping[str, int]],
    received: Callable[[_N], Mapping[str, int]] | None,
) -> None:
    """:func:`run_node`'s end: the counts written, the node destroyed, rclpy shut down.

    A further signal is only recorded from here on: the counts are written however the node
    stopped.
    """
    interrupt_on_signals(record_signal)
    for node in built:
        write_counts(name, published(node), received(node) if received else None)
        node.destroy_node()
    built.clear()
    rclpy.try_shutdown()


def _wants_help(argv: Sequence[str]) -> bool:
    """Whether ``-h`` or ``--help`` stands before ``--ros-args`` (the node's own arguments)."""
    own = argv[1 : argv.index('--ros-args')] if '--ros-args' in argv else argv[1:]
    return any(arg in ('-h', '--help') for arg in own)


def params_file_problem(argv: Sequence[str]) -> str | None:
    """What is wrong with the ``--params-file`` files of ``--ros-args``, naming the file.

    rcl reads them in ``rclpy.init`` and, on a missing or broken one, logs only that it
    failed to parse its arguments; the node would then start without its parameters.

    Args:
        argv: The command line.

    Returns:
        One line, or ``None`` when every file given is a ROS 2 parameter file.
    """
    from lumpbeam_ros.base.paramfile import read_parameter_file

    inside = False
    for i, arg in enumerate(argv):
        if arg == '--ros-args':
            inside = True
        elif arg == '--':
            inside = False
        elif inside and arg == '--params-file':
            if i + 1 >= len(argv):
                return '--params-file needs a file'
            try:
                read_parameter_file(argv[i + 1])
            except LumpbeamError as exc:
                return str(exc)
    return None


#: Longest time :func:`spin_events` stays in the executor before it looks at the context and
#: lets Python run its signal handlers, s.
EVENTS_POLL_S = 0.1


def spin_events(node: Node) -> None:
    """Spins a node on rclpy's events executor until its context shuts down.

    ``rclpy.spin``'s executor rebuilds its wait set from every entity of the node (a dozen
    with the parameter services) in Python on each wake; at 180 frames a second that was a
    third of the camera node's CPU and half of the identifier's (doc/validation.md,
    'Speed'). The events executor dispatches each event from C++. It is rclpy's experimental
    executor: its timers followed ``/clock`` in a check with rclpy 7.1.5, but rclcpp's events
    executor's do not, so a node whose timers must follow ``/clock`` spins with
    :func:`spin_live`, which keeps rclpy's own executor on a simulated clock.
    Its own ``spin`` only returns when the context's Python shutdown runs, which rclpy's
    signal handler does not call: the loop returns to Python every :data:`EVENTS_POLL_S` to
    see the context shut down and to run the signal handlers.

    That executor logs an exception leaving a callback as FATAL, with its stack, before it
    passes it on; a signal's interrupt in a callback that computes, or a publish the
    shutdown cut into, is the stop, not a fault (:func:`run_node`). So the node's
    subscription and timer callbacks hand what they raise to this loop, which raises it as
    ``rclpy.spin`` would, and no callback runs after it.

    Args:
        node: The node; its context is the one watched.
    """
    from rclpy.experimental import EventsExecutor

    raised: list[BaseException] = []
    for entity in (*node.subscriptions, *node.timers):
        entity.callback = _raising_in_the_loop(entity.callback, raised)
    executor = EventsExecutor(context=node.context)
    executor.add_node(node)
    try:
        while node.context.ok() and not raised:
            executor.spin_once(timeout_sec=EVENTS_POLL_S)
        if raised:
            raise raised[0]
    finally:
        executor.shutdown()


def _raising_in_the_loop(
    callback: Callable[..., Any], raised: list[BaseException]
) -> Callable[..., Any]:
    """``callback``, keeping what it raises in ``raised`` (see :func:`spin_events`)."""

    # wraps: rclpy reads the callback's signature (message only, or with its info).
    @functools.wraps(callback)
    def call(*args: Any) -> Any:
        if raised:
            return None
        try:
            return callback(*args)
        except BaseException as exc:  # noqa: BLE001 - raised again by spin_events' loop
            raised.append(exc)
            return None

    return call


def live_spinner(node: Node) -> Callable[[Node], None]:
    """How :func:`spin_live` spins ``node``: by its clock, read once at the start.

    Args:
        node: The node, its ``use_sim_time`` parameter set.

    Returns:
        :func:`spin_events` on wall time; ``rclpy.spin`` with ``use_sim_time``, whose timers
        follow ``/clock`` in every rclpy release (a bag replayed with ``lumpbeam play``).
    """
    return rclpy.spin if node.get_parameter('use_sim_time').value else spin_events


def spin_live(node: Node) -> None:
    """Spins a node fed at camera rate whose timers follow the ROS clock (:func:`live_spinner`).

    Args:
        node: The node; its context is the one watched.
    """
    live_spinner(node)(node)


def checked_namespace(namespace: str | None) -> str:
    """A node namespace given on the command line, checked by rclpy's validator.

    Args:
        namespace: An absolute namespace (``'/beam_a'``); ``None`` or ``''`` for none.

    Returns:
        The namespace (``''`` for none).

    Raises:
        LumpbeamError: rclpy rejects it; the message is its first line (what is wrong).
    """
    if not namespace:
        return ''
    try:
        validate_namespace(namespace)
    except InvalidNamespaceException as exc:
        reason = str(exc).splitlines()[0].removeprefix('Invalid namespace: ').rstrip(':')
        raise LumpbeamError(f'--namespace {namespace!r}: {reason}') from None
    return namespace


def checked_topics(topics: Sequence[str]) -> list[str]:
    """Topic names given on the command line, checked by rclpy's validator.

    Args:
        topics: Topic names (``'/tip_pose'``; a relative name is taken in the node's
            namespace; ``~`` and ``{}`` substitutions are refused).

    Returns:
        The names, unchanged.

    Raises:
        LumpbeamError: rclpy rejects one; the message names it and says what is wrong.
    """
    for topic in topics:
        try:
            validate_topic_name(topic)
            # The full name's rules too (no '//'), as the topic would have in the root.
            validate_full_topic_name(topic if topic.startswith('/') else f'/{topic}')
        except InvalidTopicNameException as exc:
            reason = str(exc).splitlines()[0].split(': ', 1)[-1].rstrip(':')
            raise LumpbeamError(f'topic {topic!r}: {reason}') from None
    return list(topics)


class StopRequest:
    """Whether SIGINT or SIGTERM asked a command to stop (see :func:`stoppable_session`).

    Attributes:
        signal: The signal received, ``None`` while none came.
    """

    def __init__(self) -> None:
        self.signal: int | None = None

    @property
    def requested(self) -> bool:
        """Whether a stop was asked for."""
        return self.signal is not None

    def _handle(self, signum: int, _frame: FrameType | None) -> None:
        self.signal = signum


@contextmanager
def stoppable_session() -> Iterator[StopRequest]:
    """An rclpy session whose SIGINT and SIGTERM only ask the caller's loop to stop.

    rclpy's own handlers would shut the context down at once; a recorder then loses what is
    still on its way and a player cannot finish its statistics. The handlers are restored
    and rclpy shut down on exit.

    Yields:
        The stop request the caller's loop polls.
    """
    stop = StopRequest()
    previous = interrupt_on_signals(stop._handle)
    try:
        rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
        yield stop
    finally:
        rclpy.try_shutdown()
        restore_handlers(previous)
