"""``lumpbeam campaign BAGS... --out RESULTS``: analyze (and diagnose) many bags on Dask."""

from __future__ import annotations

import argparse
import sys


def run(args: argparse.Namespace) -> int:
    """Expands the bags, runs the campaign, prints its summary, writes the report."""
    from lumpbeam_ros.apps.campaign.bags import expand_bags
    from lumpbeam_ros.apps.campaign.engine import run_campaign
    from lumpbeam_ros.apps.campaign.store import ResultsStore
    from lumpbeam_ros.apps.campaign.summary import summarize, write_campaign_report
    from lumpbeam_ros.apps.campaign.task import CampaignOptions
    from lumpbeam_ros.core.ident.settings import load_identifier_config
    from lumpbeam_ros.core.model.parameters import load_beam_config

    bags = expand_bags(args.bags)
    beam, _ = load_beam_config(args.config)
    settings = CampaignOptions(beam, load_identifier_config(args.identifier_config), args.diagnose)
    store = ResultsStore(args.out)
    result = run_campaign(
        bags,
        store,
        settings,
        scheduler=args.scheduler,
        workers=args.workers,
        stream=sys.stderr,
        timeout_s=args.connect_timeout,
    )
    rate = (
        f' ({result.submitted / result.seconds:.2f} bags/s)'
        if result.submitted and result.seconds > 0
        else ''
    )
    print(
        f'{len(bags)} bags: {result.submitted} run on {result.workers} workers in '
        f'{result.seconds:.1f} s{rate}, {result.skipped} already done, {result.failed} failed'
    )
    summary = summarize(store.completed(), beam)
    print(summary.text())
    report = write_campaign_report(summary, store.folder / 'report.html')
    print(f'wrote {store.parquet_path}, {store.csv_path}, {report}')
    # Some bad bags are what a campaign expects; none at all working is worth an exit code.
    return 1 if result.failed and result.failed == result.submitted else 0
