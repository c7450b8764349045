"""The shipped Foxglove layout and RViz config against the demo's bag.

Every topic a panel uses is in the bag, with the type the panel needs, and every plotted
path selects numbers.
"""

import json
import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from arm_cases import small_arm

from lumpbeam_ros.base.resources import config_path
from lumpbeam_ros.core.bagio import BagReader, BagWriter
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.synthetic.arm_bag import ArmSynthOptions, write_arm_bag
from lumpbeam_ros.core.viz.layouts import (
    check_uses,
    evaluate,
    foxglove_uses,
    load_foxglove_layout,
    rviz_uses,
    split_message_path,
)
from lumpbeam_ros.core.viz.marker_messages import read_marker_arrays

ROOT = Path(__file__).resolve().parents[3]
#: Topics doc/interfaces.md marks planned: a layout may show them before any node has them.
PLANNED = set(re.findall(r'`(/[\w/]+)` \(planned\)', (ROOT / 'doc' / 'interfaces.md').read_text()))
#: Topics only an arm has: checked against an arm's bag, not the beam demo's.
ARM_TOPICS = {'/joint_states'}


@pytest.fixture(scope='module')
def demo_bag(demo_results):
    """The demo's sim-time recording (the session's one demo run)."""
    assert demo_results.exit_code == 0, demo_results.printed
    return demo_results.out / 'bags' / 'recorded_sim_time'


def _uses():
    layout = load_foxglove_layout(config_path('foxglove_layout.json'))
    return foxglove_uses(layout) + rviz_uses(config_path('lumpbeam.rviz'))


def test_layouts_use_the_topics_the_issue_asks_for():
    used = {(u.panel.split('!')[0], u.topic) for u in _uses()}
    assert {('3D', '/beam_markers'), ('3D', '/tip_pose'), ('3D', '/tip_pose_predicted')} <= used
    paths = {u.topic + u.path for u in _uses()}
    assert {'/tip_pose.pose.position.z', '/tip_pose_predicted.pose.position.z'} <= paths
    for key in ('natural_frequency_hz', 'damping_ratio'):
        for name in (key, f'{key}_std'):
            assert f'/beam_params.status[0].values[:]{{key=="{name}"}}.value' in paths
    assert any(u.topic == '/model_discrepancy' for u in _uses())
    rviz = {(u.topic, u.msgtype) for u in rviz_uses(config_path('lumpbeam.rviz'))}
    assert rviz == {
        ('/beam_markers', 'visualization_msgs/msg/MarkerArray'),
        ('/tip_pose', 'geometry_msgs/msg/PoseStamped'),
        ('/tip_pose_predicted', 'geometry_msgs/msg/PoseStamped'),
    }


def test_every_panel_topic_is_in_the_demo_bag_with_its_type(demo_bag):
    uses = [u for u in _uses() if u.topic not in PLANNED | ARM_TOPICS]
    assert len(uses) >= 12
    assert check_uses(uses, demo_bag) == []
    topics = BagReader(demo_bag).topics
    assert topics['/beam_markers'].count >= 30  # a 30 Hz stream over the run


def test_the_arm_is_served_by_an_arm_bag(tmp_path):
    t = np.arange(0.0, 0.2 + 1e-9, 0.01)
    move = JointTrajectory(t, np.outer(t, [1.0, -1.0, 0.5]))
    write_arm_bag(tmp_path / 'arm', small_arm(3), move, ArmSynthOptions(duration_s=0.3))
    uses = [u for u in _uses() if u.topic in ARM_TOPICS | {'/beam_markers', '/tip_pose'}]
    assert {u.topic for u in uses} == {'/joint_states', '/beam_markers', '/tip_pose'}
    assert check_uses(uses, tmp_path / 'arm') == []
    _, markers = next(read_marker_arrays(tmp_path / 'arm'))
    assert {m.namespace for m in markers} >= {'arm_link', 'arm_joints'}
    rviz = yaml.safe_load(config_path('lumpbeam.rviz').read_text())
    display = next(
        d
        for d in rviz['Visualization Manager']['Displays']
        if d.get('Name', '').endswith('(/beam_markers)')
    )
    assert {'arm_link', 'arm_joints', 'beam'} <= {k for k, v in display['Namespaces'].items() if v}


def test_no_panel_shows_a_planned_topic():
    # A topic no node publishes yet could not be checked against the demo's recording.
    assert {u.topic for u in _uses()} & PLANNED == set()


def test_check_reports_a_missing_topic_a_wrong_type_and_an_empty_path(tmp_path):
    bag = tmp_path / 'bag'
    with BagWriter(bag) as writer:
        writer.write_pose('/beam_markers', 0.0, 1.0, 0.0, 0.0)  # a pose, not markers
        writer.write_pose('/tip_pose', 0.0, 2.3, -0.05, 0.0)
    layout = json.loads(config_path('foxglove_layout.json').read_text())
    problems = '\n'.join(check_uses(foxglove_uses(layout), bag))
    assert '/beam_params: not in the bag' in problems
    assert '/tip_pose_predicted: not in the bag' in problems
    assert 'rviz' not in problems
    rviz = '\n'.join(check_uses(rviz_uses(config_path('lumpbeam.rviz')), bag))
    assert 'geometry_msgs/msg/PoseStamped in the bag, the panel needs visualization_msgs' in rviz


@pytest.mark.parametrize(
    ('path', 'topic', 'segments'),
    [
        ('/tip_pose.pose.position.z', '/tip_pose', [('field', 'pose'), ('field', 'position'),
                                                    ('field', 'z')]),
        ('/a/b.status[0].values[:]{key=="x_std"}.value', '/a/b',
         [('field', 'status'), ('index', '0'), ('field', 'values'), ('index', ':'),
          ('filter', 'key=="x_std"'), ('field', 'value')]),
    ],
)  # fmt: skip
def test_split_message_path(path, topic, segments):
    assert split_message_path(path) == (topic, segments)


@pytest.mark.parametrize('bad', ['tip_pose.z', '/tip_pose.pose..z', '/tip_pose[x]'])
def test_split_message_path_refuses_other_syntax(bad):
    with pytest.raises(ValueError, match='message path'):
        split_message_path(bad)


def test_evaluate_filters_key_values():
    from lumpbeam_ros.core.bagio import convert

    msg = convert.diagnostic_array(
        0, [convert.Status('s', 0, '', {'a': '1.5', 'a_std': '0.1'})], 'beam_base'
    )
    _, segments = split_message_path('/d.status[0].values[:]{key=="a_std"}.value')
    assert evaluate(msg, segments) == ['0.1']
    _, missing = split_message_path('/d.status[1].values[:]{key=="a"}.value')
    assert evaluate(msg, missing) == []
    with pytest.raises(ValueError, match='no field'):
        evaluate(msg, split_message_path('/d.statuses')[1])


def test_layout_tree_and_panels_must_agree(tmp_path):
    layout = json.loads(config_path('foxglove_layout.json').read_text())
    layout['layout']['first'] = 'Plot!nowhere'
    bad = tmp_path / 'layout.json'
    bad.write_text(json.dumps(layout))
    with pytest.raises(ValueError, match='panels placed'):
        load_foxglove_layout(bad)
