"""The demo's accounting: what was published against what was recorded.

Per topic, the messages published (the player's and the nodes' own counters) against those
recorded, and the camera frames offered against those tracked.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from lumpbeam_ros.apps.demo.run import (
    IMAGE_TOPIC,
    PUBLISHERS,
    RECORDED_TOPICS,
    DemoRun,
)
from lumpbeam_ros.base.interface import (
    CAMERA_NODE,
    TIP_POSE,
)
from lumpbeam_ros.core.bagio import BagReader
from lumpbeam_ros.nodes.counts import read_counts


def count(run: DemoRun) -> None:
    """Sets what was published against what was recorded, per topic, and prints it."""
    counts = read_counts(run.counts_dir)
    recorded = {name: entry.count for name, entry in BagReader(run.recorded_bag).topics.items()}
    publishers = dict(PUBLISHERS)
    if run.with_camera:
        publishers[TIP_POSE] = CAMERA_NODE
    run.topic_counts = {}
    for topic in RECORDED_TOPICS:
        publisher = publishers[topic]
        published = counts.get(publisher, {}).get('published', {}).get(topic)
        run.topic_counts[topic] = {
            'publisher': publisher,
            'published': published,
            'recorded': recorded.get(topic, 0),
        }
    if run.with_camera:
        camera = counts.get(CAMERA_NODE, {})
        run.image_counts = {
            'offered': counts.get('player', {}).get('published', {}).get(IMAGE_TOPIC),
            'received': camera.get('received', {}).get(IMAGE_TOPIC),
            'tracked': camera.get('published', {}).get(TIP_POSE),
        }
    for line in count_lines(run.topic_counts, run.image_counts):
        run.echo(line)


def count_lines(
    topic_counts: Mapping[str, Mapping[str, Any]], image_counts: Mapping[str, int | None]
) -> list[str]:
    """The table of :func:`count`: published, recorded and lost per topic."""
    lines = [f'  {"topic":<22}{"publisher":<16}{"published":>10}{"recorded":>10}{"lost":>6}']
    for topic, row in topic_counts.items():
        published = row['published']
        lost = '-' if published is None else str(published - row['recorded'])
        shown = '-' if published is None else str(published)
        lines.append(
            f'  {topic:<22}{row["publisher"]:<16}{shown:>10}{row["recorded"]:>10}{lost:>6}'
        )
    if image_counts:
        shown = {k: '-' if v is None else str(v) for k, v in image_counts.items()}
        lines.append(
            f'  {IMAGE_TOPIC}: {shown["offered"]} frames offered by the player, '
            f'{shown["received"]} received by the camera node (best effort), '
            f'{shown["tracked"]} tracked'
        )
    return lines
