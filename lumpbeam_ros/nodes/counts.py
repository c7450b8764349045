"""What a node published and received, left in a file when it exits (ROS-free).

A graph's owner (``lumpbeam demo``) sets :data:`COUNTS_DIR_ENV` for its children; each node
then writes ``<dir>/<name>.json`` on exit, ``{"published": {topic: n}, "received": {topic:
n}}``, from its own counters. Set against the recorded bag, these counts show where a
message was lost: never published, or lost between publisher and recorder.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path

#: Environment variable naming the folder of the counts files; unset: nothing is written.
COUNTS_DIR_ENV = 'LUMPBEAM_COUNTS_DIR'


def write_counts(
    name: str, published: Mapping[str, int], received: Mapping[str, int] | None = None
) -> Path | None:
    """Writes a node's counts when :data:`COUNTS_DIR_ENV` is set.

    Args:
        name: The node's name (the file's stem).
        published: Messages it published, per topic.
        received: Messages it took in, per topic.

    Returns:
        The file written, or ``None`` when the variable is unset or the file cannot be
        written (a node's exit never fails on it).
    """
    folder = os.environ.get(COUNTS_DIR_ENV)
    if not folder:
        return None
    path = Path(folder) / f'{name}.json'
    counts = {'published': dict(published), 'received': dict(received or {})}
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        partial = path.with_suffix('.json.part')
        partial.write_text(json.dumps(counts, indent=1, sort_keys=True), encoding='utf-8')
        partial.replace(path)  # a reader never sees half a file
    except OSError:
        return None
    return path


def read_counts(folder: Path) -> dict[str, dict[str, dict[str, int]]]:
    """Reads every node's counts in a folder, by node name (a damaged file is skipped)."""
    counts = {}
    for path in sorted(Path(folder).glob('*.json')):
        try:
            data = json.loads(path.read_text(encoding='utf-8'))
        except (OSError, ValueError):
            continue
        if isinstance(data, dict):
            counts[path.stem] = data
    return counts
