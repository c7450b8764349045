"""Runs a campaign on Dask: a local cluster (processes, one thread each) or a scheduler.

Bags already in the results with the same key (path, content fingerprint, settings) and
no error are skipped; every finished bag is added to the table as it arrives, and the table
is flushed at least once a second, so an interrupted campaign keeps what it completed.
"""

from __future__ import annotations

import logging
import multiprocessing
import time
from collections.abc import Sequence
from contextlib import ExitStack
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from lumpbeam_ros.apps.campaign.bags import fingerprint
from lumpbeam_ros.apps.campaign.store import ResultsStore
from lumpbeam_ros.apps.campaign.task import (
    CampaignOptions,
    Row,
    error_line,
    process_bag,
    row_key,
    warm_up,
)
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.progress import Progress

#: Seconds to wait for a scheduler given by address before giving up.
CONNECT_TIMEOUT_S = 10.0
#: How long an abandoned worker process is given to end once told to, s.
_ABANDONED_WORKER_JOIN_S = 5.0


@dataclass(frozen=True)
class CampaignRun:
    """What one ``lumpbeam campaign`` run did.

    Attributes:
        store: The results (every row, this run's and earlier ones).
        submitted: Bags processed in this run.
        skipped: Bags already done with the same key.
        failed: Bags of this run whose row has an error.
        seconds: Wall time of the processing (cluster start excluded).
        workers: Workers the cluster had.
    """

    store: ResultsStore
    submitted: int
    skipped: int
    failed: int
    seconds: float
    workers: int


def pending_bags(
    bags: Sequence[Path], store: ResultsStore, settings: CampaignOptions
) -> list[str]:
    """The bags that have no finished row with their current key.

    Raises:
        LumpbeamError: A bag cannot be read to fingerprint it.
    """
    digest = settings.digest()
    pending = []
    for bag in bags:
        try:
            content = fingerprint(bag)
        except OSError as exc:
            raise LumpbeamError(f'{bag}: cannot read it ({exc.strerror or exc})') from None
        if not store.is_done(str(bag), row_key(str(bag), content, digest)):
            pending.append(str(bag))
    return pending


def start_client(
    scheduler: str | None, workers: int, stack: ExitStack, timeout_s: float = CONNECT_TIMEOUT_S
) -> object:
    """A Dask client: on ``scheduler``, or on a new local cluster of ``workers`` processes.

    Args:
        scheduler: Address of a running scheduler (``tcp://host:8786``), or ``None``.
        workers: Worker processes of a local cluster, one thread each.
        stack: Closes the client and the cluster when it exits.
        timeout_s: How long to wait for ``scheduler`` to answer, s.

    Returns:
        A ``distributed.Client``.

    Raises:
        LumpbeamError: Dask is not installed, or no scheduler answers at ``scheduler``.
    """
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise LumpbeamError(
            'lumpbeam campaign needs Dask: pip install "lumpbeam_ros[campaign]" '
            '(dask, distributed, pyarrow)'
        ) from None
    if scheduler is None:
        from distributed.deploy.spec import SpecCluster

        registered = set(SpecCluster._instances)
        children = set(multiprocessing.active_children())
        try:
            cluster = LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                silence_logs=50,
            )
        except BaseException:
            # A cluster registers itself for distributed's exit-time cleanup before its
            # workers start; one whose start a signal cut short fails an assertion there (a
            # traceback after "interrupted"). Its worker processes are multiprocessing
            # children, which the interpreter ends at exit anyway.
            SpecCluster._instances.difference_update(set(SpecCluster._instances) - registered)
            # The cluster's own loop goes on in its thread, and a worker start it abandons
            # fails there; asyncio logs that task's exception, traceback and all, when the
            # task is collected at exit.
            logging.getLogger('asyncio').setLevel(logging.CRITICAL)
            # A worker still starting reads its start-up state (a semaphore among it) from
            # this process; once this one has exited the semaphore is gone, and the worker
            # prints a traceback of its own. Ended first, it has nothing to print.
            for child in set(multiprocessing.active_children()) - children:
                child.terminate()
                child.join(_ABANDONED_WORKER_JOIN_S)
            raise
        stack.enter_context(cluster)
        return stack.enter_context(Client(cluster))
    try:
        client = Client(scheduler, timeout=timeout_s)
    except (OSError, TimeoutError, ValueError) as exc:
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise LumpbeamError(
            f'--scheduler {scheduler}: no Dask scheduler answered within '
            f'{timeout_s:g} s ({reason})'
        ) from None
    return stack.enter_context(client)


def run_campaign(
    bags: Sequence[Path],
    store: ResultsStore,
    settings: CampaignOptions,
    *,
    scheduler: str | None = None,
    workers: int = 2,
    stream: TextIO | None = None,
    timeout_s: float = CONNECT_TIMEOUT_S,
) -> CampaignRun:
    """Processes the pending bags on Dask and adds their rows to the store.

    Args:
        bags: The bag folders (absolute).
        store: The results; rows are added and flushed as bags finish.
        settings: Beam, identifier settings, and whether to diagnose.
        scheduler: A scheduler's address, or ``None`` for a local cluster.
        workers: Worker processes of the local cluster.
        stream: Where the progress bar goes (stderr; drawn only on a terminal).
        timeout_s: How long to wait for ``scheduler`` to answer, s.

    Returns:
        What the run did.

    Raises:
        LumpbeamError: As :func:`start_client`, or the results cannot be written.
    """
    pending = pending_bags(bags, store, settings)
    skipped = len(bags) - len(pending)
    if not pending:
        return CampaignRun(store, 0, skipped, 0, 0.0, 0)
    with ExitStack() as stack:
        from distributed import as_completed

        client = start_client(scheduler, workers, stack, timeout_s)
        n_workers = len(client.scheduler_info()['workers'])  # type: ignore[attr-defined]
        client.run(warm_up)  # type: ignore[attr-defined]  # imports are not bag time
        start = time.perf_counter()
        futures = {
            client.submit(process_bag, bag, settings, pure=False): bag  # type: ignore[attr-defined]
            for bag in pending
        }
        failed = _collect(
            as_completed(futures),
            futures,
            store,
            Progress(len(pending), 'campaign', stream, long_job=None),
        )
        seconds = time.perf_counter() - start
    return CampaignRun(store, len(pending), skipped, failed, seconds, n_workers)


def _collect(
    finished: object, futures: dict[object, str], store: ResultsStore, progress: Progress
) -> int:
    """Adds each finished bag's row; a task that died (a killed worker) gets an error row."""
    failed = 0
    try:
        for future in finished:  # type: ignore[attr-defined]
            bag = futures[future]
            if future.status == 'finished':
                row = future.result()
            else:
                exc = future.exception()
                row = {'path': bag, 'error': f'task failed: {error_line(exc)}'}
            store.add(row)
            failed += bool(row.get('error'))
            progress.tick(note=f'{failed} failed' if failed else '')
    finally:
        progress.close()
        store.flush_if_dirty()
    return failed


def run_serial(bags: Sequence[Path], settings: CampaignOptions) -> list[Row]:
    """The same rows by a plain loop in this process (the baseline of ``lumpbeam bench``).

    Args:
        bags: The bag folders.
        settings: As for :func:`run_campaign`.

    Returns:
        One row per bag, in order.
    """
    return [process_bag(str(bag), settings) for bag in bags]
