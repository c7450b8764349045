import os
import time

from lumpbeam_lab.bench.load import busy_loops


def _cpu_s() -> float:
    times = os.times()
    return times.children_user + times.children_system


def test_the_loops_take_cpu_while_the_block_runs_and_are_gone_after():
    before = _cpu_s()
    with busy_loops(1):
        time.sleep(0.5)
    # Reaped on exit, so their CPU time is counted: a loop that spun for most of the block.
    assert _cpu_s() - before > 0.1


def test_no_loops():
    before = _cpu_s()
    with busy_loops(0):
        pass
    assert _cpu_s() == before
