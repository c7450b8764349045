"""``lumpbeam analyze BAG``: identification of a recorded drop test (doc/interfaces.md)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from lumpbeam_ros.cli.output import write_json
from lumpbeam_ros.errors import LumpbeamError
from lumpbeam_ros.ident.bag_analysis import (
    CONTRACT_KEYS,
    POSE_TOPIC,
    analyze_bag,
    read_window,
    result_json,
)
from lumpbeam_ros.ident.settings import load_identifier_config
from lumpbeam_ros.model.parameters import load_beam_config
from lumpbeam_ros.progress import Progress

__all__ = ['CONTRACT_KEYS', 'Progress', 'read_window', 'result_json', 'run']


def run(args: argparse.Namespace) -> int:
    """Reads the bag, identifies the whole record, prints a summary, writes JSON and plots."""
    if args.fit_links or args.arm:
        from lumpbeam_ros.cli.fit_links import run_fit_links

        return run_fit_links(args)
    if len(args.bag) > 1:
        raise LumpbeamError(f'{len(args.bag)} bags given: several bags only with --fit-links')
    args.bag = args.bag[0]
    beam, _ = load_beam_config(args.config)
    config = load_identifier_config(args.identifier_config)
    analysis = analyze_bag(args.bag, beam, config)
    window, result = analysis.window, analysis.result
    for note in analysis.notes:
        print(f'lumpbeam analyze: warning: {args.bag}: {POSE_TOPIC}: {note}', file=sys.stderr)
    print(f'{args.bag}: {len(window)} poses over {window.end_s - window.start_s:.2f} s')
    print(result.summary())
    if args.json:
        write_json(args.json, result_json(result))
    if args.plots:
        from lumpbeam_ros.plots.analysis import write_analysis_plots

        for path in write_analysis_plots(window, result, Path(args.plots)):
            print(f'wrote {path}')
    if args.report:
        from lumpbeam_ros.report.analysis import write_analysis_report

        print(f'wrote {write_analysis_report(analysis, args.report)}')
    return 0 if result.ok else 1
