"""SCHED_FIFO for a node's threads, or one line saying why not; the parameter's bounds."""

import json
import subprocess
import sys

import pytest

from lumpbeam_ros.nodes.realtime import REALTIME_PRIORITY, set_realtime_priority

#: A process with a second thread (as the middleware's), asking for ``priority``; prints the
#: answer and every thread's policy and priority. A subprocess: the test runner's own
#: threads stay on the normal scheduler.
_PROBE = """
import json, os, sys, threading
from lumpbeam_ros.nodes.realtime import set_normal_scheduling, set_realtime_priority
started = threading.Event()
threading.Thread(target=lambda: (started.set(), threading.Event().wait(5)), daemon=True).start()
started.wait()
problem = set_realtime_priority(int(sys.argv[1]))
late = threading.Thread(target=lambda: threading.Event().wait(5), daemon=True)
late.start()
def policies():
    return {tid: (os.sched_getscheduler(int(tid)), os.sched_getparam(int(tid)).sched_priority)
            for tid in os.listdir('/proc/self/task')}
threads = policies()
back = set_normal_scheduling()
print(json.dumps({'problem': problem, 'threads': threads, 'fifo': os.SCHED_FIFO,
                  'back': back, 'after': policies(), 'other': os.SCHED_OTHER}))
"""


def _probe(priority: int) -> dict:
    run = subprocess.run(
        [sys.executable, '-c', _PROBE, str(priority)], capture_output=True, text=True, timeout=60
    )
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout)


def test_every_thread_goes_fifo_or_the_node_is_told_why_not():
    found = _probe(20)
    policies = {tuple(policy) for policy in found['threads'].values()}
    if found['problem']:
        # No CAP_SYS_NICE nor rtprio limit here: one line, and nothing changed.
        assert 'not permitted' in found['problem'] and '\n' not in found['problem']
        assert all(policy != found['fifo'] for policy, _ in policies)
    else:
        # The threads there before and the one started after (it inherits).
        assert len(found['threads']) == 3 and policies == {(found['fifo'], 20)}
        # And back, all of them.
        assert found['back'] == ''
        assert {tuple(p) for p in found['after'].values()} == {(found['other'], 0)}


def test_zero_leaves_the_scheduler_alone():
    assert set_realtime_priority(0) == ''
    found = _probe(0)
    assert found['problem'] == '' and all(p != found['fifo'] for p, _ in found['threads'].values())


@pytest.mark.parametrize(('value', 'ok'), [(0, True), (99, True), (-1, False), (100, False)])
def test_the_parameter_takes_0_to_99(value, ok):
    assert (REALTIME_PRIORITY.problem(value) is None) == ok
