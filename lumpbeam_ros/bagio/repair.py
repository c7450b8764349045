"""Rebuilding ``metadata.yaml`` from a bag's MCAP data (``ros2 bag reindex`` for MCAP).

:class:`~lumpbeam_ros.bagio.writer.BagWriter` keeps ``metadata.yaml`` current to its last
flush, so a killed recording opens as it is. This covers the rest: a metadata file that was
deleted or damaged, or counts that lag behind the data after a crash.
"""

from __future__ import annotations

from pathlib import Path

import yaml

from lumpbeam_ros.bagio import metadata
from lumpbeam_ros.bagio.qos import from_dict
from lumpbeam_ros.bagio.reader import stream_messages
from lumpbeam_ros.bagio.typestore import is_known, type_description
from lumpbeam_ros.errors import BagError


def reindex(path: str | Path) -> int:
    """Scans a bag folder's single ``.mcap`` file and writes a matching ``metadata.yaml``.

    Topics, types, offered QoS (stored per channel in the MCAP) and exact message counts come
    from the data; an incomplete last record is skipped with a warning.

    Args:
        path: The bag folder.

    Returns:
        The number of messages found.

    Raises:
        BagError: No folder, not exactly one ``.mcap`` file, or it cannot be read or written.
    """
    folder = Path(path)
    if not folder.is_dir():
        raise BagError(f'{folder}: not a bag folder')
    files = sorted(folder.glob('*.mcap'))
    if len(files) != 1:
        raise BagError(f'{folder}: reindex needs exactly one .mcap file, found {len(files)}')
    data_file = files[0]
    counts: dict[str, int] = {}
    types: dict[str, str] = {}
    qos: dict[str, list] = {}
    start, end = 2**63 - 1, 0
    try:
        with data_file.open('rb') as stream:
            for schema, channel, message in stream_messages(stream, str(data_file)):
                topic = channel.topic
                if topic not in counts:
                    counts[topic] = 0
                    types[topic] = schema.name if schema is not None else ''
                    profiles = yaml.safe_load(channel.metadata.get('offered_qos_profiles', ''))
                    qos[topic] = [from_dict(p) for p in profiles or [] if isinstance(p, dict)]
                counts[topic] += 1
                start = min(start, message.log_time)
                end = max(end, message.log_time)
        topics = [
            (
                name,
                types[name],
                n,
                qos[name],
                type_description(types[name])[1] if is_known(types[name]) else '',
            )
            for name, n in counts.items()
        ]
        metadata.write(folder, metadata.build(data_file.name, topics, start, end))
    except OSError as exc:
        raise BagError(f'{folder}: cannot reindex: {exc.strerror or exc}') from None
    return sum(counts.values())
