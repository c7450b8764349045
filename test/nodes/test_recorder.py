"""The recorder node, in process on the test's own ROS domain."""

from __future__ import annotations

import pytest
from mcap.reader import make_reader
from std_msgs.msg import Float64

from lumpbeam_ros.core.bagio import BagWriter
from lumpbeam_ros.nodes.recorder import Recorder


def _log_times(bag_dir) -> dict[str, list[int]]:
    """Log times per topic, read with the mcap package (not the product's reader)."""
    (path,) = bag_dir.glob('*.mcap')
    times: dict[str, list[int]] = {}
    with path.open('rb') as handle:
        for _, channel, message in make_reader(handle).iter_messages(log_time_order=False):
            times.setdefault(channel.topic, []).append(message.log_time)
    return times


@pytest.mark.parametrize('queued', [5, 40])
def test_log_time_is_the_delivery_time_not_the_callback_time(ros_graph, tmp_path, queued):
    # A busy recorder takes one message per subscription per turn of its executor: a reading
    # published after a burst on another topic runs its callback before most of the burst. Its
    # log time must still come after the burst's, as the messages were delivered.
    burst = ros_graph.node.create_publisher(Float64, '/burst', 100)
    after = ros_graph.node.create_publisher(Float64, '/after', 10)
    bag = BagWriter(tmp_path / 'bag', flush_period_s=10.0)
    recorder = Recorder(bag, ['/burst', '/after'], context=ros_graph.context)
    ros_graph.add_node(recorder)
    assert ros_graph.spin_until(lambda: not recorder.missing(), timeout=10.0)
    assert ros_graph.spin_until(
        lambda: burst.get_subscription_count() and after.get_subscription_count(), timeout=10.0
    )
    ros_graph.spin_for(0.3)  # the subscriptions settle on the publishers
    for i in range(queued):
        burst.publish(Float64(data=float(i)))
    after.publish(Float64(data=-1.0))
    assert ros_graph.spin_until(
        lambda: recorder.received.get('/burst') == queued and recorder.received.get('/after'),
        timeout=10.0,
    )
    bag.close()
    times = _log_times(tmp_path / 'bag')
    assert len(times['/burst']) == queued
    assert times['/after'][0] >= max(times['/burst'])
    assert times['/burst'] == sorted(times['/burst'])
