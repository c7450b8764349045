"""Campaign scaling: the same bags on a Dask LocalCluster of 1 and 2 workers, in bags/s.

- ``campaign_dask_1_worker`` and ``campaign_dask_2_workers``: bags per second through
  :func:`~lumpbeam_ros.apps.campaign.engine.run_campaign` (cluster start excluded, each run into
  a fresh results folder so nothing is skipped). Baseline: the same bags through a plain
  loop in this process (:func:`~lumpbeam_ros.apps.campaign.engine.run_serial`), timed in the same
  run, after the same imports (:func:`~lumpbeam_ros.apps.campaign.task.warm_up`). A short bag
  is analysed in a fraction of a second, so the per-task overhead of Dask (pickling, the
  scheduler's round trips) weighs on the ratio; on a machine with fewer free cores than
  workers the 2-worker rate cannot double.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

from lumpbeam_lab.bench.bench_result import BenchResult
from lumpbeam_ros.apps.campaign.engine import run_campaign, run_serial
from lumpbeam_ros.apps.campaign.store import ResultsStore
from lumpbeam_ros.apps.campaign.task import CampaignOptions, warm_up
from lumpbeam_ros.core.ident.settings import load_identifier_config
from lumpbeam_ros.core.model.parameters import DropTestConfig, load_beam_config
from lumpbeam_ros.core.synthetic.campaign_bags import write_campaign
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions

LOADS = (0.5, 1.0, 2.0, 5.0, 10.0)


def run(quick: bool = False) -> list[BenchResult]:
    """Runs the campaign benchmark.

    Args:
        quick: Two 4 s bags instead of ten 8 s bags.

    Returns:
        One result per worker count, against the plain loop.
    """
    beam, _ = load_beam_config()
    settings = CampaignOptions(beam, load_identifier_config())
    duration = 4.0 if quick else 8.0
    loads, seeds = (LOADS[:2], 1) if quick else (LOADS, 2)
    with tempfile.TemporaryDirectory(prefix='lumpbeam-bench-') as tmp:
        bags = write_campaign(
            Path(tmp) / 'bags',
            beam,
            DropTestConfig(duration_s=duration),
            SynthOptions(duration_s=duration),
            loads,
            seeds,
        )
        warm_up()
        start = time.perf_counter()
        serial = run_serial(bags, settings)
        loop_rate = len(bags) / (time.perf_counter() - start)
        results = []
        for workers in (1, 2):
            store = ResultsStore(Path(tmp) / f'out{workers}')
            campaign = run_campaign(bags, store, settings, workers=workers)
            rate = campaign.submitted / campaign.seconds
            same = all(
                store.rows[row['path']]['natural_frequency_hz'] == row['natural_frequency_hz']
                for row in serial
            )
            results.append(
                BenchResult(
                    name=f'campaign_dask_{workers}_worker{"s" if workers > 1 else ""}',
                    value=rate,
                    unit='bags/s',
                    baseline='plain loop over the same bags in this process',
                    baseline_value=loop_rate,
                    ratio=rate / loop_rate,
                    details={
                        'bags': len(bags),
                        'bag_duration_s': duration,
                        'failed': campaign.failed,
                        'same_rows_as_loop': same,
                        'cpu_count': os.cpu_count() or 0,
                    },
                )
            )
    return results
