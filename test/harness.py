"""Launch-free fixtures for tests that run real ROS 2 nodes in the test process.

Every test gets its own ``rclpy`` Context on its own ROS domain, claimed for the test's
duration (:mod:`lumpbeam_ros.nodes.ros_domain`), so tests never see each other's topics, even when
pytest-xdist runs them in several workers at once, and no ``launch`` or daemon is needed.
Discovery stays on this machine (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``).

Use it from any test (``test/conftest.py`` registers the fixture, importing this module and
rclpy only for the tests that take it)::

    def test_echo(ros_graph):
        from std_msgs.msg import Float64
        node = MyNode(context=ros_graph.context)      # the node under test
        ros_graph.add_node(node)                      # spun by the graph's executor
        got = ros_graph.collect('/out', Float64)      # subscribe before publishing
        ros_graph.publish('/in', Float64(data=4.5))
        assert ros_graph.spin_until(lambda: len(got) >= 1, timeout=5.0)
        assert got[0].data == 4.5

The camera, identifier and simulator node tests reuse it. A node under test must accept a
``context`` (``rclpy.node.Node(name, context=...)``). ``ros_graph.domain_id`` is also what a
node started as a subprocess needs (``env={'ROS_DOMAIN_ID': ...}``, see :func:`ros_env`); a
test without a graph that needs a domain of its own takes the ``ros_domain_id`` fixture.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import QoSProfile, qos_profile_sensor_data

from lumpbeam_ros.nodes.ros_domain import PRIVATE_DOMAIN_IDS, DomainClaim, claim_domain_id

# Fast DDS maps domain ids to UDP ports; 0..101 and 215..232 are valid on Linux for any
# number of participants. Domain 0 is left to a developer's own ROS graph.
TEST_DOMAIN_IDS = [*PRIVATE_DOMAIN_IDS, *range(215, 233)]


def claim_test_domain() -> DomainClaim:
    """Claims a domain of :data:`TEST_DOMAIN_IDS` that no other process holds."""
    return claim_domain_id(TEST_DOMAIN_IDS)


def ros_env(domain_id: int, root: Path | None = None) -> dict[str, str]:
    """Returns the environment for a ROS subprocess on ``domain_id``.

    Args:
        domain_id: The test's domain.
        root: Where ROS logs go (``.cache/ros`` under the working directory when ``None``).

    Returns:
        A copy of ``os.environ`` with the domain, local discovery and the log folder set.
    """
    root = root or Path.cwd() / '.cache' / 'ros'
    env = dict(os.environ)
    env.update(
        ROS_DOMAIN_ID=str(domain_id),
        ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
        ROS_LOG_DIR=str(root / 'log'),
        ROS_HOME=str(root),
    )
    return env


class RosGraph:
    """A private ROS 2 graph: one Context, one executor and a helper node.

    Args:
        domain_id: The ROS domain to use.

    Attributes:
        context: Pass it to nodes under test.
        domain_id: The domain.
        executor: A ``SingleThreadedExecutor`` spinning every added node.
        node: The helper node that publishes and collects.
    """

    def __init__(self, domain_id: int):
        self.domain_id = domain_id
        self.context = Context()
        rclpy.init(context=self.context, domain_id=domain_id)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.node = Node('test_harness', context=self.context)
        self.executor.add_node(self.node)
        self._publishers: dict[str, Any] = {}

    def add_node(self, node: Node) -> None:
        """Spins ``node`` together with the helper node."""
        self.executor.add_node(node)

    def publish(self, topic: str, msg: Any, qos: QoSProfile | int = 10) -> None:
        """Publishes ``msg`` (a publisher per topic is created on first use).

        Args:
            topic: Topic name.
            msg: A message instance (its class fixes the topic's type).
            qos: Profile or depth.
        """
        if topic not in self._publishers:
            self._publishers[topic] = self.node.create_publisher(type(msg), topic, qos)
        self._publishers[topic].publish(msg)

    def wait_for_subscribers(self, topic: str, count: int = 1, timeout: float = 5.0) -> bool:
        """Spins until ``topic``'s publisher (see :meth:`publish`) sees ``count`` subscribers."""
        publisher = self._publishers[topic]
        return self.spin_until(lambda: publisher.get_subscription_count() >= count, timeout)

    def collect(
        self, topic: str, msg_type: type, qos: QoSProfile | int = 10, raw: bool = False
    ) -> list[Any]:
        """Subscribes to ``topic`` and returns the list that received messages are appended to.

        Args:
            topic: Topic name.
            msg_type: Message class.
            qos: Profile or depth; use ``qos_profile_sensor_data`` for best-effort publishers.
            raw: Receive serialized bytes instead of messages.

        Returns:
            A list that fills while the graph spins.
        """
        received: list[Any] = []
        self.node.create_subscription(msg_type, topic, received.append, qos, raw=raw)
        return received

    def spin_until(self, predicate: Callable[[], bool], timeout: float = 5.0) -> bool:
        """Spins the executor until ``predicate()`` is true or ``timeout`` seconds pass.

        Returns:
            Whether the predicate became true.
        """
        deadline = time.monotonic() + timeout
        while not predicate():
            if time.monotonic() > deadline:
                return False
            self.executor.spin_once(timeout_sec=0.01)
        return True

    def spin_for(self, seconds: float) -> None:
        """Spins for a fixed time (to let discovery or a publisher settle)."""
        self.spin_until(lambda: False, seconds)

    def set_clock(self, nodes: list[Node], seconds: float, timeout: float = 5.0) -> None:
        """Publishes ``/clock`` and spins until every node (under ``use_sim_time``) reads it."""
        from rosgraph_msgs.msg import Clock

        msg = Clock()
        target = round(seconds * 1e9)
        msg.clock.sec, msg.clock.nanosec = divmod(target, 1_000_000_000)
        self.publish('/clock', msg)
        assert self.spin_until(
            lambda: all(n.get_clock().now().nanoseconds == target for n in nodes), timeout
        )

    def shutdown(self) -> None:
        """Destroys the nodes and the context."""
        self.executor.shutdown()
        for node in list(self.executor.get_nodes()):
            node.destroy_node()
        rclpy.shutdown(context=self.context)


SENSOR_QOS = qos_profile_sensor_data


#: Longest time a node or a command may take to exit after SIGINT or SIGTERM, s.
STOP_BOUND_S = 2.0


def start_process(env: dict[str, str], *argv: str) -> subprocess.Popen[str]:
    """Starts ``python -m ARGV...`` (a node's module or ``lumpbeam_ros.apps.cli.main ...``).

    Args:
        env: Its environment (:func:`ros_env`).
        *argv: The module and its arguments.

    Returns:
        The process, its output captured as text.
    """
    return subprocess.Popen(
        [sys.executable, '-m', *argv],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def stop_with(
    process: subprocess.Popen[str], sig: signal.Signals, bound_s: float = STOP_BOUND_S
) -> tuple[int, str, str]:
    """Sends ``sig`` and waits at most ``bound_s`` for the process to exit.

    A process still running then is killed, and the test fails with its output.

    Returns:
        The exit code, stdout and stderr.
    """
    process.send_signal(sig)
    try:
        stdout, stderr = process.communicate(timeout=bound_s)
    except subprocess.TimeoutExpired:
        process.kill()
        stdout, stderr = process.communicate()
        pytest.fail(f'still running {bound_s} s after {sig.name}; stderr: {stderr[-3000:]}')
    return process.returncode, stdout, stderr


def open_ros_graph(monkeypatch: pytest.MonkeyPatch) -> Iterator[RosGraph]:
    """A private ROS graph for one test (the ``ros_graph`` fixture, ``test/conftest.py``)."""
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    log_dir = Path.cwd() / '.cache' / 'ros' / 'log'
    log_dir.mkdir(parents=True, exist_ok=True)
    monkeypatch.setenv('ROS_LOG_DIR', str(log_dir))
    with claim_test_domain() as claim:
        graph = RosGraph(claim.domain_id)
        try:
            yield graph
        finally:
            graph.shutdown()


def held_domain_id() -> Iterator[int]:
    """A domain id held for one test (the ``ros_domain_id`` fixture, ``test/conftest.py``)."""
    with claim_test_domain() as claim:
        yield claim.domain_id


def arm_status_msg(arm: Any, level: int = 0, **changes: float) -> Any:
    """A ``/arm_params`` message of ``arm``'s links as the identifier encodes them.

    Each link's k_total and damping_beta with 0.1 % and 5 % stds, three ring-downs;
    ``changes`` replace KeyValues (``link_1_damping_beta=nan``).
    """
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

    from lumpbeam_ros.base.interface import ARM_STATUS
    from lumpbeam_ros.core.ident.arm.learner import ArmEstimate
    from lumpbeam_ros.core.ident.arm.link_fit import LinkEstimate, link_stiffness_total
    from lumpbeam_ros.core.ident.identification import Status

    links = tuple(
        LinkEstimate(
            link_stiffness_total(link),
            1e-3 * link_stiffness_total(link),
            link.damping_beta,
            0.05 * link.damping_beta,
        )
        for link in arm.links
    )
    values = dict(ArmEstimate(Status(level), 'fitted', 3, links=links).key_values())
    values.update({k: repr(float(v)) for k, v in changes.items()})
    status = DiagnosticStatus(level=bytes([level]), name=ARM_STATUS, message='fitted')
    status.values = [KeyValue(key=k, value=v) for k, v in values.items()]
    return DiagnosticArray(status=[status])
