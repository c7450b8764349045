"""One bag's row of the campaign table: what a Dask worker runs, and the plain loop runs.

The row holds the bag's path, key and metadata, then the JSON keys of ``lumpbeam analyze``
and (with the diagnosis) ``lumpbeam diagnose`` flattened to columns (``gap_before.rms_m``;
lists as JSON text), and ``error``: empty, or one line saying why the bag gave no result.
The work is :func:`~lumpbeam_ros.core.ident.bag_analysis.analyze_bag` and
:func:`~lumpbeam_ros.core.diagnose.workflow.diagnose`, exactly what the two commands call.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
import traceback
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from lumpbeam_ros.apps.campaign.bags import bag_facts, fingerprint
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.model.parameters import BeamParameters

#: Version of the table's layout; a results file of another version is not appended to.
SCHEMA_VERSION = 1

#: The columns every row has, in this order, before the results.
ID_COLUMNS = (
    'path',
    'key',
    'content_hash',
    'settings_hash',
    'schema_version',
    'error',
    'diagnosed',
    'duration_s',
    'start_time',
    'message_count',
    'pose_count',
    'load_count',
    'load_kg',
    'elapsed_s',
)

Row = dict[str, Any]


@dataclass(frozen=True)
class CampaignOptions:
    """What every bag of a campaign is analysed with.

    Attributes:
        beam: The beam (L, g, masses for B.12; the nominal model of the diagnosis).
        identifier: Identifier settings.
        diagnose: Also run the diagnosis.
    """

    beam: BeamParameters
    identifier: IdentifierConfig
    diagnose: bool = False

    def digest(self) -> str:
        """A hash of the settings: a row computed with other settings is not reused."""
        text = json.dumps(
            [asdict(self.beam), asdict(self.identifier), self.diagnose],
            sort_keys=True,
            default=str,
        )
        return hashlib.sha256(text.encode()).hexdigest()[:16]


def row_key(path: str, content_hash: str, settings_hash: str) -> str:
    """The key a rerun recognises a finished bag by: its path, content and settings."""
    return hashlib.sha256(f'{path}\0{content_hash}\0{settings_hash}'.encode()).hexdigest()[:32]


def flatten(data: dict[str, Any], prefix: str = '') -> Row:
    """A JSON dictionary as flat columns: nested keys joined by ``.``, lists as JSON text.

    Args:
        data: A command's JSON dictionary.
        prefix: Prepended to every key.

    Returns:
        ``{column: scalar}``; NaN and infinity become ``None`` (``null`` inside lists).
    """
    out: Row = {}
    for key, value in data.items():
        name = f'{prefix}{key}'
        if isinstance(value, dict):
            out.update(flatten(value, f'{name}.'))
            continue
        plain = _plain(value)
        # allow_nan=False: NaN is not JSON; _plain has made every non-finite number null.
        out[name] = json.dumps(plain, allow_nan=False) if isinstance(plain, list) else plain
    return out


def _plain(value: Any) -> Any:
    """A value as plain Python for JSON: numpy to Python, tuples to lists, NaN and inf to None."""
    if hasattr(value, 'tolist'):  # a numpy scalar or array
        value = value.tolist()
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def error_line(exc: BaseException) -> str:
    """One line for the ``error`` column: the product's own message, else type and place."""
    if isinstance(exc, LumpbeamError):
        return str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    frames = traceback.extract_tb(exc.__traceback__)
    where = f' (at {Path(frames[-1].filename).name}:{frames[-1].lineno})' if frames else ''
    text = str(exc).splitlines()[0] if str(exc) else ''
    return f'{type(exc).__name__}: {text}{where}'


def process_bag(bag: str, settings: CampaignOptions) -> Row:
    """Analyses (and diagnoses) one bag into its row; never raises for a bad bag.

    Args:
        bag: The bag folder, absolute.
        settings: The campaign's settings.

    Returns:
        The row: identity and metadata, the results, and ``error`` (empty when the bag
        gave its results).
    """
    from lumpbeam_ros.core.ident.bag_analysis import analyze_bag, result_json

    start = time.perf_counter()
    path = Path(bag)
    settings_hash = settings.digest()
    row: Row = {
        'path': str(path),
        'settings_hash': settings_hash,
        'schema_version': SCHEMA_VERSION,
        'diagnosed': settings.diagnose,
        'error': '',
    }
    try:
        facts = bag_facts(path)  # first: a folder that is no bag gets the reader's message
        row['content_hash'] = fingerprint(path)
        row['key'] = row_key(str(path), row['content_hash'], settings_hash)
        row.update(asdict(facts))
        analysis = analyze_bag(path, settings.beam, settings.identifier, show_progress=False)
        row.update(flatten(result_json(analysis.result)))
        row['load_kg'] = row.get('released_load_kg')
        if not analysis.result.ok:
            row['error'] = f'analyze: no estimate ({analysis.result.message})'
        if settings.diagnose:
            from lumpbeam_ros.core.diagnose.measurement import read_record
            from lumpbeam_ros.core.diagnose.workflow import diagnose

            row.update(flatten(diagnose(read_record(path), settings.beam).as_dict()))
    except Exception as exc:  # noqa: BLE001 - a bad bag is a row, the campaign goes on
        row['error'] = error_line(exc)
    row.setdefault('content_hash', '')
    row.setdefault('key', row_key(str(path), row['content_hash'], settings_hash))
    row['elapsed_s'] = time.perf_counter() - start
    return row


def warm_up() -> None:
    """Imports what :func:`process_bag` needs, so a worker's first bag is not timed with it."""
    import lumpbeam_ros.core.diagnose.workflow  # noqa: F401
    import lumpbeam_ros.core.ident.bag_analysis  # noqa: F401
