"""The interface's names against doc/interfaces.md, and how nodes resolve them."""

import re
from pathlib import Path

import pytest

from lumpbeam_ros.base import interface
from lumpbeam_ros.base.interface import TOPIC_TYPES, in_namespace, node_topic

DOC = (Path(__file__).parents[2] / 'doc' / 'interfaces.md').read_text(encoding='utf-8')


def test_every_topic_has_the_type_the_doc_lists():
    rows = dict(re.findall(r'^\| `(/[a-z_/]+)` \| `([a-z_]+/msg/[A-Za-z0-9]+)`', DOC, re.M))
    assert rows == TOPIC_TYPES


@pytest.mark.parametrize(
    'name', [interface.IDENTIFIER_STATUS, interface.DIAGNOSIS_STATUS, interface.CAMERA_STATUS]
)
def test_status_names_are_the_documented_ones(name):
    assert f'status `{name}`' in DOC


@pytest.mark.parametrize(
    ('topic', 'namespace', 'relative', 'resolved'),
    [
        ('/tip_pose', '', 'tip_pose', '/tip_pose'),
        ('/tip_pose', '/', 'tip_pose', '/tip_pose'),
        ('/tip_load', '/beam_a', 'tip_load', '/beam_a/tip_load'),
        ('/camera/image_raw', '/rig/beam_b/', 'camera/image_raw', '/rig/beam_b/camera/image_raw'),
        ('/clock', '/beam_a', '/clock', '/clock'),
        ('/diagnostics', '/beam_a', '/diagnostics', '/diagnostics'),
    ],
)
def test_nodes_name_topics_relative_but_for_the_graph_wide_ones(
    topic, namespace, relative, resolved
):
    assert node_topic(topic) == relative
    assert in_namespace(topic, namespace) == resolved


@pytest.mark.parametrize('bad', ['tip_pose', ''])
def test_a_relative_name_is_refused(bad):
    with pytest.raises(ValueError, match='not an absolute topic name'):
        node_topic(bad)
