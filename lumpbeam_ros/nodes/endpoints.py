"""A node's publishers and subscriptions of the interface's topics, created one way.

Every node creates its endpoints here, so that each one:

- takes the topic's :func:`~lumpbeam_ros.base.interface.node_topic` name: relative, so a
  namespace (``--ros-args -r __ns:=/beam_a``) or a remap moves it, and exactly the
  interface's name (``/tip_pose``) without one;
- takes the project's profile of the topic (:func:`~lumpbeam_ros.nodes.msgtypes.topic_qos`),
  so both ends of a topic agree;
- lets parameters override that profile's history, depth and reliability (rclpy's
  :class:`~rclpy.qos_overriding_options.QoSOverridingOptions`): read-only parameters
  ``qos_overrides.<resolved topic>.<publisher|subscription>.<policy>``, e.g.
  ``qos_overrides./tip_pose.publisher.depth``, set by ``--params-file`` or ``-p``. A value
  rclpy cannot use (a depth below 1, an unknown policy name, the wrong type) is a
  :class:`~lumpbeam_ros.base.errors.ConfigError` naming the parameter, so the node stops at start
  with one line (exit code 2).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from rcl_interfaces.msg import SetParametersResult
from rclpy.exceptions import ParameterException
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.qos import HistoryPolicy, QoSProfile
from rclpy.qos_overriding_options import InvalidQosOverridesError, QoSOverridingOptions
from rclpy.subscription import Subscription

from lumpbeam_ros.base.errors import ConfigError
from lumpbeam_ros.base.interface import node_topic
from lumpbeam_ros.nodes.msgtypes import topic_qos


def _check_overrides(profile: QoSProfile) -> SetParametersResult:
    """Refuses an overridden profile that DDS would refuse with an unreadable error."""
    if profile.history == HistoryPolicy.KEEP_LAST and profile.depth < 1:
        return SetParametersResult(successful=False, reason=f'depth {profile.depth} < 1')
    return SetParametersResult(successful=True)


def _create(node: Node, kind: str, topic: str, create: Callable[..., Any]) -> Any:
    """Creates an endpoint with the overridable profile; a bad override is a ConfigError."""
    name = node_topic(topic)
    options = QoSOverridingOptions.with_default_policies(callback=_check_overrides)
    try:
        return create(name, topic_qos(topic), qos_overriding_options=options)
    except (ParameterException, InvalidQosOverridesError, RuntimeError) as exc:
        key = f'qos_overrides.{node.resolve_topic_name(name)}.{kind}'
        raise ConfigError(f'{node.get_name()} parameters', key, str(exc)) from None


def publisher(node: Node, msg_class: type[Any], topic: str) -> Publisher:
    """Creates ``node``'s publisher of an interface topic.

    Args:
        node: The publishing node.
        msg_class: The message class, e.g. ``PoseStamped``.
        topic: The interface's (absolute) name, e.g. ``'/tip_pose'``.

    Returns:
        The publisher.

    Raises:
        ConfigError: A ``qos_overrides`` parameter of the topic is invalid.
    """

    def create(name: str, qos: QoSProfile, **options: Any) -> Publisher:
        return node.create_publisher(msg_class, name, qos, **options)

    return _create(node, 'publisher', topic, create)


def subscription(
    node: Node,
    msg_class: type[Any],
    topic: str,
    callback: Callable[[Any], None],
    raw: bool = False,
) -> Subscription:
    """Creates ``node``'s subscription to an interface topic.

    Args:
        node: The subscribing node.
        msg_class: The message class.
        topic: The interface's (absolute) name, e.g. ``'/tip_load'``.
        callback: Called with each message (its CDR bytes with ``raw``).
        raw: Receive serialized bytes.

    Returns:
        The subscription.

    Raises:
        ConfigError: A ``qos_overrides`` parameter of the topic is invalid.
    """

    def create(name: str, qos: QoSProfile, **options: Any) -> Subscription:
        return node.create_subscription(msg_class, name, callback, qos, raw=raw, **options)

    return _create(node, 'subscription', topic, create)
