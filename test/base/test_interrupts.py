"""SIGINT and SIGTERM: the exit code a command returns is the one the process ends with."""

from __future__ import annotations

import gc
import signal
import subprocess
import sys

import pytest

from lumpbeam_ros.base import interrupts
from lumpbeam_ros.base.interrupts import SignalInterrupt, raise_interrupt, signal_number

#: ``lumpbeam doctor`` whose work is generated code that receives the signal: what a
#: command meets when the signal lands while a dataclass or namedtuple is being created, or
#: in rosbags' generated serializers (all run through ``exec``).
GENERATED_CODE_COMMAND = """
import sys
from lumpbeam_ros.apps.cli import main as cli

SIGNAL = {sig}
WORK = 'import os\\nos.kill(os.getpid(), SIGNAL)\\nwhile True:\\n    pass'
cli.load_target = lambda target: lambda args: exec(WORK, {{'SIGNAL': SIGNAL}})
sys.exit(cli.main(['doctor', 'any']))
"""


@pytest.mark.parametrize('sig', [signal.SIGINT, signal.SIGTERM], ids=lambda s: s.name)
def test_an_interrupt_in_generated_code_keeps_the_commands_exit_code(tmp_path, sig):
    """Under ``python -m``, CPython ended such a process with -2 after its line.

    An exact ``KeyboardInterrupt`` that once left ``exec``'d code marks the process as killed
    by SIGINT, and only ``-m`` returns its exit code through the check of that mark (a script
    and ``-c`` exit from ``sys.exit`` directly).
    """
    (tmp_path / 'generated_work.py').write_text(GENERATED_CODE_COMMAND.format(sig=int(sig)))
    process = subprocess.run(
        [sys.executable, '-m', 'generated_work'],
        capture_output=True,
        text=True,
        timeout=60,
        cwd=tmp_path,
    )
    assert process.returncode == 128 + sig, process.stderr
    assert process.stderr.strip() == 'lumpbeam doctor: interrupted'


@pytest.fixture(autouse=True)
def _process_state(monkeypatch):
    # raise_interrupt records the signal and swaps the unraisable hook for the process.
    monkeypatch.setattr(interrupts, '_received', [])
    monkeypatch.setattr(sys, 'unraisablehook', sys.unraisablehook)


def test_the_interrupt_names_its_signal():
    with pytest.raises(KeyboardInterrupt) as caught:
        raise_interrupt(signal.SIGTERM, None)
    assert isinstance(caught.value, SignalInterrupt)
    assert signal_number(caught.value) == signal.SIGTERM
    assert signal_number(KeyboardInterrupt()) == signal.SIGINT


def test_a_recorded_signal_raises_nothing_and_is_remembered(monkeypatch):
    monkeypatch.setattr(interrupts, '_received', [])
    previous = interrupts.interrupt_on_signals(interrupts.record_signal)
    try:
        signal.raise_signal(signal.SIGINT)
    finally:
        interrupts.restore_handlers(previous)
    assert interrupts.interrupted()


#: run_script in a process of its own: what it returns, and how much of the heap it froze.
RUN_SCRIPT = """
import gc, os, signal, sys
from lumpbeam_ros.base.interrupts import run_script

def load():
    if sys.argv[1] == 'signal':
        os.kill(os.getpid(), signal.SIGTERM)
        while True:
            pass
    return lambda: 7

code = run_script(load, lambda signum: 100 + signum)
print(gc.get_freeze_count(), signal.getsignal(signal.SIGINT) is signal.SIG_DFL)
sys.exit(code)
"""


@pytest.mark.parametrize('when', ['done', 'signal'])
def test_run_script_returns_the_code_and_freezes_the_heap(when):
    """A signal during the loading is the interrupted code; either way the heap is frozen.

    The frozen objects are skipped by the interpreter's shutdown collections (the diagnosis
    node's stop spent most of its time there); a signal after the work ends the process.
    """
    process = subprocess.run(
        [sys.executable, '-c', RUN_SCRIPT, when], capture_output=True, text=True, timeout=60
    )
    assert process.returncode == (100 + signal.SIGTERM if when == 'signal' else 7)
    frozen, default_handler = process.stdout.split()
    assert int(frozen) > 1000 and default_handler == 'True'


class _HalfBuilt:
    def __init__(self, interrupt: bool) -> None:
        if interrupt:
            raise_interrupt(signal.SIGTERM, None)
        raise RuntimeError('not built')

    def __del__(self) -> None:
        self.never_set.clear()


@pytest.mark.parametrize('interrupted', [True, False], ids=['after an interrupt', 'otherwise'])
def test_a_half_built_objects_destructor_is_quiet_only_after_an_interrupt(
    monkeypatch, interrupted
):
    reported = []
    monkeypatch.setattr(sys, 'unraisablehook', reported.append)
    with pytest.raises((SignalInterrupt, RuntimeError)):
        _HalfBuilt(interrupted)
    gc.collect()
    assert [r.exc_type for r in reported] == ([] if interrupted else [AttributeError])
