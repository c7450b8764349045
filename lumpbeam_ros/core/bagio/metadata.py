"""``metadata.yaml`` of a rosbag2 directory (format version 9, as ROS 2 Jazzy writes it).

``ros2 bag info`` and rosbags read a bag through this file: the storage plugin, the data
files, the time span and, per topic, the type, serialization, offered QoS profiles and
message count. The writer refreshes it while recording so that a bag whose recorder was
killed still opens; :func:`load` checks what a reader relies on.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final

import yaml
from rosbags.interfaces import Qos

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.base.paramfile import safe_load

VERSION: Final = 9
FILENAME = 'metadata.yaml'


def is_bag(path: str | Path) -> bool:
    """Tells whether ``path`` is a rosbag2 folder (it holds ``metadata.yaml``)."""
    return (Path(path) / FILENAME).is_file()


@dataclass(frozen=True)
class TopicEntry:
    """A topic as the metadata lists it.

    Attributes:
        name: Topic name.
        msgtype: Full type name, e.g. ``'std_msgs/msg/Float64'``.
        count: Messages recorded (a lower bound in a bag whose recording was cut).
        qos: Offered QoS profiles, as ``ros2 bag`` writes them (list of dicts).
        type_hash: RIHS01 type description hash, empty when unknown.
    """

    name: str
    msgtype: str
    count: int
    qos: list[dict[str, Any]]
    type_hash: str = ''


def dump_qos(profiles: Sequence[Qos]) -> list[dict[str, Any]]:
    """QoS profiles in rosbag2's version 9 form, as ``metadata.yaml`` lists them.

    rosbags.rosbag2 is imported only here: it brings its own reader, writer and ruamel.yaml,
    which a command that only reads a bag (``lumpbeam analyze``) does not need at start-up.

    Args:
        profiles: The profiles.

    Returns:
        One mapping per profile.
    """
    from rosbags.rosbag2.metadata import dump_qos_v9

    return [dict(profile) for profile in dump_qos_v9(list(profiles))]


def build(
    data_file: str,
    topics: Sequence[tuple[str, str, int, Sequence[Qos], str]],
    start_ns: int,
    end_ns: int,
) -> dict[str, Any]:
    """Builds the metadata mapping of a single-file MCAP bag.

    Args:
        data_file: The .mcap file name, relative to the bag folder.
        topics: ``(name, msgtype, count, offered_qos, rihs01)`` per topic.
        start_ns: Earliest log time, ns (ignored when there are no messages).
        end_ns: Latest log time, ns.

    Returns:
        The mapping to dump as YAML.
    """
    count = sum(t[2] for t in topics)
    start = start_ns if count else 0
    duration = max(0, end_ns - start_ns) if count else 0
    return {
        'rosbag2_bagfile_information': {
            'version': VERSION,
            'storage_identifier': 'mcap',
            'duration': {'nanoseconds': duration},
            'starting_time': {'nanoseconds_since_epoch': start},
            'message_count': count,
            'topics_with_message_count': [
                {
                    'topic_metadata': {
                        'name': name,
                        'type': msgtype,
                        'serialization_format': 'cdr',
                        'offered_qos_profiles': dump_qos(qos),
                        'type_description_hash': rihs01,
                    },
                    'message_count': n,
                }
                for name, msgtype, n, qos, rihs01 in topics
            ],
            'compression_format': '',
            'compression_mode': '',
            'relative_file_paths': [data_file],
            'files': [
                {
                    'path': data_file,
                    'starting_time': {'nanoseconds_since_epoch': start},
                    'duration': {'nanoseconds': duration},
                    'message_count': count,
                }
            ],
            'custom_data': None,
            'ros_distro': 'jazzy',
        }
    }


def write(folder: Path, metadata: dict[str, Any]) -> None:
    """Writes ``metadata.yaml`` atomically (a reader never sees half a file).

    Raises:
        OSError: The file cannot be written.
    """
    target = folder / FILENAME
    tmp = target.with_suffix('.yaml.tmp')
    # libyaml's emitter when PyYAML has it: a recorder rewrites this file at every flush
    # (every 1 MiB of images), and the pure-Python one took ~40 ms of each.
    dumper = getattr(yaml, 'CSafeDumper', yaml.SafeDumper)
    text = yaml.dump(metadata, Dumper=dumper, sort_keys=False)
    tmp.write_text(text, encoding='utf-8')
    os.replace(tmp, target)


@dataclass(frozen=True)
class BagInfo:
    """What a reader needs from ``metadata.yaml``.

    Attributes:
        files: Absolute paths of the data files, in order.
        topics: Topic entries by name.
        start_ns: Starting time, ns.
        duration_ns: Duration, ns.
        message_count: Total messages according to the metadata.
    """

    files: list[Path]
    topics: dict[str, TopicEntry]
    start_ns: int
    duration_ns: int
    message_count: int


def load(folder: Path) -> BagInfo:
    """Reads and checks ``metadata.yaml`` of a bag folder.

    Args:
        folder: The bag folder.

    Returns:
        The parsed metadata.

    Raises:
        BagError: Not a folder, no or unreadable metadata, a storage other than mcap or
            compression, or missing fields or data files.
    """
    if not folder.exists():
        raise BagError(f'{folder}: no such bag')
    if not folder.is_dir():
        raise BagError(f'{folder}: not a bag folder (a rosbag2 bag is a folder with {FILENAME})')
    path = folder / FILENAME
    if not path.is_file():
        raise BagError(f'{folder}: not a rosbag2 bag (no {FILENAME})')
    try:
        raw = safe_load(path.read_text(encoding='utf-8'))
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise BagError(f'{path}: unreadable metadata ({first})') from None
    if not isinstance(raw, dict) or not isinstance(raw.get('rosbag2_bagfile_information'), dict):
        raise BagError(f'{path}: not rosbag2 metadata (no rosbag2_bagfile_information)')
    info = raw['rosbag2_bagfile_information']
    try:
        storage = info['storage_identifier']
        if storage != 'mcap':
            raise BagError(f'{folder}: storage {storage!r} is not supported, only mcap')
        if info.get('compression_mode'):
            raise BagError(
                f'{folder}: {info["compression_mode"]} compression is not supported '
                '(MCAP chunk compression is)'
            )
        files = [folder / str(name) for name in info['relative_file_paths']]
        topics = {}
        for item in info['topics_with_message_count'] or []:
            meta = item['topic_metadata']
            qos = meta.get('offered_qos_profiles') or []
            if isinstance(qos, str):  # version <= 8 stores the profiles as a YAML string
                qos = safe_load(qos) or []
            topics[meta['name']] = TopicEntry(
                name=str(meta['name']),
                msgtype=str(meta['type']),
                count=int(item['message_count']),
                qos=list(qos),
                type_hash=str(meta.get('type_description_hash') or ''),
            )
        bag_info = BagInfo(
            files=files,
            topics=topics,
            start_ns=int(info['starting_time']['nanoseconds_since_epoch']),
            duration_ns=int(info['duration']['nanoseconds']),
            message_count=int(info['message_count']),
        )
    except (KeyError, TypeError, ValueError, yaml.YAMLError) as exc:
        problem = f'{type(exc).__name__}: {exc}'
        raise BagError(f'{path}: malformed rosbag2 metadata ({problem})') from None
    if not files:
        raise BagError(f'{path}: lists no data files')
    for file in files:
        if not file.is_file():
            raise BagError(f'{folder}: data file {file.name} listed in {FILENAME} is missing')
    return bag_info
