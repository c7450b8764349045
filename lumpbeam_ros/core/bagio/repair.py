"""Making a damaged bag whole: a new copy (``mcap recover``), or new metadata (``reindex``).

:class:`~lumpbeam_ros.core.bagio.writer.BagWriter` keeps ``metadata.yaml`` current to its last
flush, so a killed recording opens with this package's reader as it is. Other readers
(rosbags, ``ros2 bag``, the mcap tools) need the MCAP file's closing summary, which a killed
writer never wrote: :func:`repair_bag` copies every readable message into a new bag with a
summary and exact counts. :func:`reindex` covers a metadata file that was deleted or damaged.
"""

from __future__ import annotations

import shutil
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import yaml
from mcap.records import Channel, Schema

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.core.bagio import metadata
from lumpbeam_ros.core.bagio.qos import from_dict
from lumpbeam_ros.core.bagio.reader import BagReader, FileWalk, probe
from lumpbeam_ros.core.bagio.typestore import deserialize, is_known, type_description
from lumpbeam_ros.core.bagio.writer import BagWriter


def reindex(path: str | Path) -> int:
    """Scans a bag folder's single ``.mcap`` file and writes a matching ``metadata.yaml``.

    Topics, types, offered QoS (stored per channel in the MCAP) and exact message counts come
    from the data; a topic the file declares without messages is listed with a count of 0;
    an incomplete last record is skipped with a warning.

    Args:
        path: The bag folder.

    Returns:
        The number of messages found.

    Raises:
        BagError: No folder, not exactly one ``.mcap`` file, an empty or non-MCAP file, or it
            cannot be read or written.
    """
    folder = Path(path)
    if not folder.is_dir():
        raise BagError(f'{folder}: not a bag folder')
    files = sorted(folder.glob('*.mcap'))
    if len(files) != 1:
        raise BagError(f'{folder}: reindex needs exactly one .mcap file, found {len(files)}')
    data_file = files[0]
    # An empty or foreign file is no bag: write no metadata for it.
    summary = probe(data_file, folder)
    declared: dict[str, tuple[Schema | None, Channel]] = {}
    counts: dict[str, int] = {}
    start, end = 2**63 - 1, 0
    try:
        for _, channel, message in FileWalk(data_file, folder, summary, None, declared):
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            start = min(start, message.log_time)
            end = max(end, message.log_time)
        topics = []
        for name, (schema, channel) in declared.items():
            msgtype = schema.name if schema is not None else ''
            profiles = yaml.safe_load(channel.metadata.get('offered_qos_profiles', ''))
            qos = [from_dict(p) for p in profiles or [] if isinstance(p, dict)]
            type_hash = type_description(msgtype)[1] if is_known(msgtype) else ''
            topics.append((name, msgtype, counts.get(name, 0), qos, type_hash))
        metadata.write(folder, metadata.build(data_file.name, topics, start, end))
    except OSError as exc:
        raise BagError(f'{folder}: cannot reindex: {exc.strerror or exc}') from None
    return sum(counts.values())


@dataclass
class RepairSummary:
    """What :func:`repair_bag` kept.

    Attributes:
        out: The repaired bag.
        listed: Messages per topic that the damaged bag's metadata listed.
        kept: Messages per topic copied into the repaired bag.
        undecodable: Messages per topic left out because they do not decode (damaged bytes
            in a chunk without a CRC); topics without any are absent.
        truncated: Whether the damaged bag had data files without their closing summary.
    """

    out: Path
    listed: dict[str, int] = field(default_factory=dict)
    kept: dict[str, int] = field(default_factory=dict)
    undecodable: dict[str, int] = field(default_factory=dict)
    truncated: bool = False


def default_repair_path(bag: str | Path) -> Path:
    """Where ``lumpbeam repair BAG`` writes when no OUT is given: ``BAG-repaired`` beside it."""
    path = Path(bag)
    return path.with_name(f'{path.name}-repaired')


def repair_bag(bag: str | Path, out: str | Path | None = None) -> RepairSummary:
    """Copies every readable message of a bag into a new, complete bag.

    The copy has one MCAP file with chunk indexes, statistics, CRCs and summary, its messages
    in log-time order, and a ``metadata.yaml`` whose counts are those of the copy. Topics keep
    their types, message definitions, type hashes and offered QoS, those without messages
    too. What a damaged chunk or an incomplete record held is lost, and a message of a known
    type that does not decode is left out: the copy holds only what every reader can read
    (the reader warns, naming each topic and count). When the copy fails, nothing of it is
    left behind.

    Args:
        bag: The damaged bag folder (e.g. a recording whose recorder was killed).
        out: The bag folder to create; :func:`default_repair_path` when ``None``.

    Returns:
        What was kept.

    Raises:
        BagError: ``bag`` cannot be opened, ``out`` exists, or a write fails.
    """
    reader = BagReader(bag)
    target = Path(out) if out is not None else default_repair_path(reader.path)
    summary = RepairSummary(
        target,
        listed={name: entry.count for name, entry in reader.topics.items()},
        truncated=bool(reader.truncated),
    )
    writer = BagWriter(target)  # refuses an existing OUT: nothing of the user's is removed
    try:
        with writer:
            _copy(reader, writer, summary)
    except BaseException:
        shutil.rmtree(target, ignore_errors=True)
        raise
    return summary


def _copy(reader: BagReader, writer: BagWriter, summary: RepairSummary) -> None:
    """Copies the readable, decodable messages and declares every topic the bag declares."""
    declared: dict[str, tuple[Schema | None, Channel]] = {}
    read: Counter[str] = Counter()
    undecodable: Counter[str] = Counter()
    errors: dict[str, str] = {}
    for schema, channel, message in reader.iter_records(declared=declared, report=False):
        topic = channel.topic
        read[topic] += 1
        msgtype = schema.name if schema is not None else ''
        if is_known(msgtype):
            try:
                deserialize(message.data, msgtype)
            except BagError as exc:
                undecodable[topic] += 1
                errors.setdefault(topic, str(exc))
                continue
        if not writer.has_topic(topic):
            _declare(writer, reader, topic, schema)
            summary.kept[topic] = 0
        writer.write_raw(topic, message.log_time, message.data)
        summary.kept[topic] += 1
    for topic in sorted(set(reader.topics) | set(read)):
        reader.report_loss(topic, read[topic], undecodable[topic], errors.get(topic, ''))
    summary.undecodable = dict(undecodable)
    # Topics without a message: the file's own schema describes a type Jazzy lacks.
    for name, (schema, _) in declared.items():
        if not writer.has_topic(name):
            _declare(writer, reader, name, schema)
            summary.kept[name] = 0
    for name, entry in reader.topics.items():
        if not writer.has_topic(name) and is_known(entry.msgtype):
            writer.add_topic(name, entry.msgtype, qos=[from_dict(p) for p in entry.qos])
            summary.kept[name] = 0


def _declare(writer: BagWriter, reader: BagReader, topic: str, schema: object) -> None:
    """Declares a topic in the copy as the damaged bag had it."""
    entry = reader.topics.get(topic)
    msgtype = getattr(schema, 'name', '') or (entry.msgtype if entry else '')
    msgdef = None
    if getattr(schema, 'encoding', '') == 'ros2msg':
        msgdef = bytes(schema.data).decode()  # type: ignore[attr-defined]
    qos = [from_dict(p) for p in entry.qos] if entry is not None and entry.qos else None
    type_hash = entry.type_hash if entry is not None and entry.type_hash else None
    writer.add_topic(topic, msgtype, qos=qos, msgdef=msgdef, type_hash=type_hash)
