"""A node's publishers and subscriptions of the interface's topics, created one way.

Every node creates its endpoints here, so that each one:

- takes the topic's :func:`~lumpbeam_ros.interface.node_topic` name: relative, so a
  namespace (``--ros-args -r __ns:=/beam_a``) or a remap moves it, and exactly the
  interface's name (``/tip_pose``) without one;
- takes the project's profile of the topic (:func:`~lumpbeam_ros.nodes.msgtypes.topic_qos`),
  so both ends of a topic agree;
- lets parameters override that profile's history, depth and reliability (rclpy's
  :class:`~rclpy.qos_overriding_options.QoSOverridingOptions`): read-only parameters
  ``qos_overrides.<resolved topic>.<publisher|subscription>.<policy>``, e.g.
  ``qos_overrides./tip_pose.publisher.depth``, set by ``--params-file`` or ``-p``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.qos_overriding_options import QoSOverridingOptions
from rclpy.subscription import Subscription

from lumpbeam_ros.interface import node_topic
from lumpbeam_ros.nodes.msgtypes import topic_qos


def publisher(node: Node, msg_class: type[Any], topic: str) -> Publisher:
    """Creates ``node``'s publisher of an interface topic.

    Args:
        node: The publishing node.
        msg_class: The message class, e.g. ``PoseStamped``.
        topic: The interface's (absolute) name, e.g. ``'/tip_pose'``.

    Returns:
        The publisher.
    """
    return node.create_publisher(
        msg_class,
        node_topic(topic),
        topic_qos(topic),
        qos_overriding_options=QoSOverridingOptions.with_default_policies(),
    )


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
    """
    return node.create_subscription(
        msg_class,
        node_topic(topic),
        callback,
        topic_qos(topic),
        qos_overriding_options=QoSOverridingOptions.with_default_policies(),
        raw=raw,
    )
