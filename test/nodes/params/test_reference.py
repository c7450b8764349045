import subprocess
import sys
from pathlib import Path

import pytest

from lumpbeam_ros.nodes.params.reference import SCHEMAS, node_table, reference

ROOT = Path(__file__).resolve().parents[3]
COMMITTED = ROOT / 'doc' / 'parameters.md'


def test_the_committed_reference_is_the_generated_one():
    assert COMMITTED.read_text(encoding='utf-8') == reference(), (
        'doc/parameters.md is out of date: python -m lumpbeam_ros.nodes.params.reference '
        '> doc/parameters.md'
    )


def test_the_module_prints_the_reference():
    done = subprocess.run(
        [sys.executable, '-m', 'lumpbeam_ros.nodes.params.reference'],
        capture_output=True, text=True, timeout=60, check=True,
    )  # fmt: skip
    assert done.stdout == reference()


@pytest.mark.parametrize('schema', SCHEMAS, ids=lambda s: s.node)
def test_one_row_per_parameter(schema):
    table = node_table(schema)
    rows = [line for line in table.splitlines() if line.startswith('| `')]
    file_only = [spec.name for spec in schema.file_only]
    assert [row.split('`')[1] for row in rows] == schema.names + file_only
    # No '|' inside a cell breaks a table (the file's own parameters: no read-only column).
    assert [row.count(' | ') for row in rows] == [6] * len(schema.names) + [5] * len(file_only)
    assert table.startswith(f'## `{schema.node}`')


def test_a_row_carries_type_default_range_unit_and_read_only():
    table = node_table(next(s for s in SCHEMAS if s.node == 'simulator_node'))
    assert '| `rate_hz` | double | `180.0` | [1, 2000] | Hz | no |' in table
    assert "| `beam_config` | string | `''` |  |  | no |" in table
