"""The bags of a campaign: arguments expanded to bag folders, and a fingerprint of each."""

from __future__ import annotations

import glob
import hashlib
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import TIP_LOAD, TIP_POSE
from lumpbeam_ros.core.bagio import metadata

#: Data files up to this size are hashed whole (sha256 runs at several hundred MB/s);
#: larger ones by their size, first and last :data:`EDGE_BYTES` (an MCAP bag is written
#: front to back and closed by its summary at the end, so a changed bag changes there).
FULL_HASH_BYTES = 64 * 2**20
EDGE_BYTES = 2**20
_GLOB_CHARS = frozenset('*?[')


def expand_bags(arguments: Sequence[str]) -> list[Path]:
    """The bag folders named by the arguments: paths or glob patterns (``'bags/*'``).

    Args:
        arguments: As given on the command line; a pattern the shell did not expand is
            expanded here.

    Returns:
        The bag folders, absolute, each once, in the order given (a pattern's matches
        sorted).

    Raises:
        LumpbeamError: No argument, a pattern that matches nothing, a path that does not
            exist, or a path that is not a rosbag2 bag folder (no ``metadata.yaml``).
    """
    if not arguments:
        raise LumpbeamError('no bags given')
    bags: list[Path] = []
    for argument in arguments:
        if _GLOB_CHARS & set(argument):
            matches = sorted(glob.glob(argument))
            if not matches:
                raise LumpbeamError(f'{argument}: matches no file or folder')
        else:
            matches = [argument]
        for match in matches:
            path = Path(match)
            if not path.exists():
                raise LumpbeamError(f'{match}: no such bag folder')
            if not (path / metadata.FILENAME).is_file():
                raise LumpbeamError(
                    f'{match}: not a rosbag2 bag (a bag is a folder with {metadata.FILENAME})'
                )
            bags.append(path.resolve())
    return list(dict.fromkeys(bags))


def fingerprint(bag: Path) -> str:
    """A hash of a bag's content: its ``metadata.yaml`` and its data files.

    Each ``.mcap`` up to :data:`FULL_HASH_BYTES` is hashed whole, a larger one by its size
    and its first and last :data:`EDGE_BYTES`; the modification time is not used, so a
    copied bag keeps its fingerprint.

    Args:
        bag: The bag folder.

    Returns:
        A hex sha256 digest.

    Raises:
        OSError: A file cannot be read.
    """
    digest = hashlib.sha256()
    digest.update((bag / metadata.FILENAME).read_bytes())
    for file in sorted(bag.glob('*.mcap')):
        size = file.stat().st_size
        digest.update(f'{file.name}\0{size}\0'.encode())
        with file.open('rb') as stream:
            if size <= FULL_HASH_BYTES:
                for block in iter(lambda: stream.read(2**20), b''):
                    digest.update(block)
            else:
                digest.update(stream.read(EDGE_BYTES))
                stream.seek(size - EDGE_BYTES)
                digest.update(stream.read(EDGE_BYTES))
    return digest.hexdigest()


@dataclass(frozen=True)
class BagFacts:
    """What ``metadata.yaml`` says about a bag (the row's metadata columns).

    Attributes:
        duration_s: Recorded span, s.
        start_time: Time of the first message, ISO 8601 UTC.
        message_count: Messages in the bag.
        pose_count: ``/tip_pose`` messages.
        load_count: ``/tip_load`` messages.
    """

    duration_s: float
    start_time: str
    message_count: int
    pose_count: int
    load_count: int


def bag_facts(bag: Path) -> BagFacts:
    """Reads a bag's metadata.

    Raises:
        BagError: Not a readable bag.
    """
    info = metadata.load(bag)
    start = datetime.fromtimestamp(info.start_ns / 1e9, tz=timezone.utc).isoformat()
    topics = info.topics

    def count(name: str) -> int:
        return topics[name].count if name in topics else 0

    return BagFacts(
        duration_s=info.duration_ns / 1e9,
        start_time=start,
        message_count=info.message_count,
        pose_count=count(TIP_POSE),
        load_count=count(TIP_LOAD),
    )
