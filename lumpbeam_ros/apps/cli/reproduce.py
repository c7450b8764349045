"""``lumpbeam reproduce``: the paper's tables, frequencies and statics beside the paper's."""

from __future__ import annotations

import argparse
from dataclasses import asdict

from lumpbeam_ros.apps.cli.output import write_json
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.model.reproduce import (
    Comparison,
    Reproduction,
    compare_with_paper,
    paper_numbers,
    reproduce,
)


def _format(rows: list[Comparison]) -> str:
    lines = [f'{"quantity":<30} {"model":>10} {"paper":>10} {"diff":>10} {"limit":>9}']
    for row in rows:
        if row.relative:
            diff, limit = f'{row.difference:+.2%}', f'{row.tolerance:.1%}'
        else:
            diff, limit = f'{row.difference * 1e3:+.2f} mm', f'{row.tolerance * 1e3:.1f} mm'
        mark = '' if row.ok else '  OUT OF TOLERANCE'
        lines.append(
            f'{row.what:<30} {row.value:>10.4f} {row.paper:>10.4f} {diff:>10} {limit:>9}{mark}'
        )
    return '\n'.join(lines)


def result_json(result: Reproduction, rows: list[Comparison]) -> dict:
    """The JSON of doc/interfaces.md, 'Command line', plus the comparison with the paper."""
    return {
        'table_b1': [asdict(r) for r in result.table_b1],
        'table_b2': [asdict(r) for r in result.table_b2],
        'frequencies_hz': result.frequencies_hz,
        'frequencies_free_end_hz': result.frequencies_free_end_hz,
        'static_6p5kg_m': result.static_6p5kg_m,
        'comparison': [{**asdict(r), 'difference': r.difference, 'ok': r.ok} for r in rows],
        'all_within_tolerance': all(r.ok for r in rows),
    }


def run(args: argparse.Namespace) -> int:
    """Recomputes the paper's numbers and prints them beside the paper's."""
    beam, _ = load_beam_config(args.config)
    result = reproduce(beam)
    rows = compare_with_paper(result, paper_numbers())
    print(_format(rows))
    free = result.frequencies_free_end_hz
    print(
        'tip masses at the free end instead (physical default): '
        + ', '.join(f'{k} {v:.3f} Hz' for k, v in free.items())
    )
    within = sum(r.ok for r in rows)
    print(f'{within} of {len(rows)} numbers within tolerance')
    if args.json:
        write_json(args.json, result_json(result, rows))
    return 0
