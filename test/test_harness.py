import os
import subprocess
import sys

from harness import claim_test_domain, ros_env
from std_msgs.msg import Float64


def test_round_trip_through_a_private_graph(ros_graph):
    got = ros_graph.collect('/echo', Float64)
    ros_graph.publish('/echo', Float64(data=0.0))
    assert ros_graph.wait_for_subscribers('/echo')
    for value in (4.5, 0.0, 2.5):
        ros_graph.publish('/echo', Float64(data=value))
    assert ros_graph.spin_until(lambda: len(got) >= 3 and got[-1].data == 2.5, timeout=5.0)
    assert [m.data for m in got[-3:]] == [4.5, 0.0, 2.5]


def test_domains_are_distinct_and_valid():
    claims = [claim_test_domain() for _ in range(50)]
    ids = [c.domain_id for c in claims]
    for claim in claims:
        claim.release()
    assert len(set(ids)) == 50
    assert all(1 <= i <= 101 or 215 <= i <= 232 for i in ids)


def test_a_subprocess_on_another_domain_is_not_seen(ros_graph, tmp_path):
    got = ros_graph.collect('/echo', Float64)
    script = (
        'import rclpy, time\n'
        'from std_msgs.msg import Float64\n'
        'rclpy.init(); n = rclpy.create_node("p")\n'
        'pub = n.create_publisher(Float64, "/echo", 10)\n'
        'for _ in range(15):\n'
        '    pub.publish(Float64(data=1.0)); time.sleep(0.05)\n'
    )
    with claim_test_domain() as other:  # held, so no other test's graph is on it
        env = ros_env(other.domain_id, tmp_path)
        proc = subprocess.Popen([sys.executable, '-c', script], env=env)
        ros_graph.spin_until(lambda: proc.poll() is not None, timeout=60.0)
    assert proc.returncode == 0
    assert got == []
    assert os.environ.get('ROS_AUTOMATIC_DISCOVERY_RANGE') == 'LOCALHOST'
