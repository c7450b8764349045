"""How a lumpbeam process is stopped by SIGINT or SIGTERM, from its first line to its exit.

The console scripts (``lumpbeam`` and the nodes, ``setup.py``) start with
:func:`run_script`: the handlers are installed before the script imports anything heavy
(rclpy, numpy, scipy, OpenCV take seconds to import on a loaded machine), so a signal that
arrives while the modules load stops the process as one that arrives later does. Three
details make the stop quiet and prompt:

- the handlers raise :class:`SignalInterrupt`, a ``KeyboardInterrupt`` subclass. CPython
  marks a process in which an exact ``KeyboardInterrupt`` left any ``exec``'d string (a
  namedtuple or dataclass being created, generated serializers) as killed by SIGINT, and
  ends it with exit -2 even when the program caught the interrupt and returned a code;
- SIGINT is handled even when the process started with it ignored (a background job of a
  shell script, where Ctrl-C reaches the whole job): otherwise a signal that arrives during
  the imports, before a node installs its own handler, is lost and the node runs on;
- an interrupt raised inside a constructor leaves a half-built object whose ``__del__``
  then fails on an attribute never set (rclpy's ``Task``); after an interrupt, those
  ``AttributeError`` reports are dropped (:func:`quiet_half_built`), the rest still print,
  and an interrupt raised while rclpy's C++ converts a call's arguments comes out as a
  ``RuntimeError``, which a node after a signal takes as the stop (:func:`interrupted`);
- once the work is done, the objects alive are frozen out of the garbage collector
  (:func:`gc.freeze`). The interpreter's shutdown collections otherwise walk the hundreds of
  thousands of objects of scipy and rclpy, about half a second on a loaded machine; they
  free nothing a process about to exit needs freed.
"""

from __future__ import annotations

import gc
import signal
import sys
import threading
from collections.abc import Callable
from types import FrameType
from typing import Any

#: The signals that stop a command or a node.
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class SignalInterrupt(KeyboardInterrupt):
    """The interrupt raised by :func:`raise_interrupt` (see the module docstring).

    Args:
        signum: The signal received.

    Attributes:
        signum: The signal received.
    """

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


def raise_interrupt(signum: int, _frame: FrameType | None) -> None:
    """A signal handler: raises :class:`SignalInterrupt` in the main thread.

    Raises:
        SignalInterrupt: Always.
    """
    _received.append(signum)
    if sys.unraisablehook is not quiet_half_built:
        global _reported_hook
        _reported_hook = sys.unraisablehook
        sys.unraisablehook = quiet_half_built
    raise SignalInterrupt(signum)


_reported_hook = sys.unraisablehook
#: The signals :func:`raise_interrupt` has handled in this process.
_received: list[int] = []


def interrupted() -> bool:
    """Whether :func:`raise_interrupt` has handled a signal in this process."""
    return bool(_received)


def quiet_half_built(unraisable: Any) -> None:
    """The unraisable-exception hook after an interrupt (see the module docstring).

    Args:
        unraisable: What :data:`sys.unraisablehook` is given.
    """
    destructor = getattr(unraisable.object, '__name__', '') == '__del__'
    if destructor and issubclass(unraisable.exc_type, AttributeError):
        return
    _reported_hook(unraisable)


def signal_number(exc: KeyboardInterrupt) -> int:
    """The signal behind an interrupt: its own, or SIGINT for a plain ``KeyboardInterrupt``."""
    return exc.signum if isinstance(exc, SignalInterrupt) else int(signal.SIGINT)


#: What :func:`signal.signal` takes: a function, ``SIG_DFL`` or ``SIG_IGN``.
Handler = Callable[[int, FrameType | None], Any] | int | signal.Handlers


def interrupt_on_signals(handler: Handler = raise_interrupt) -> dict[int, Any]:
    """Installs ``handler`` for SIGINT and SIGTERM (nothing outside the main thread).

    Args:
        handler: The handler (default: raise :class:`SignalInterrupt`).

    Returns:
        The handlers replaced, to restore with :func:`restore_handlers`.
    """
    if threading.current_thread() is not threading.main_thread():
        return {}
    return {s: signal.signal(s, handler) for s in STOP_SIGNALS}


def record_signal(signum: int, _frame: FrameType | None) -> None:
    """A signal handler: only records the signal (:func:`interrupted`), raises nothing.

    For a cleanup that must run to its end once the work has stopped.
    """
    _received.append(signum)


def restore_handlers(previous: dict[int, Any]) -> None:
    """Puts back the handlers :func:`interrupt_on_signals` replaced."""
    for sig, handler in previous.items():
        signal.signal(sig, handler)


def run_script(
    load: Callable[[], Callable[[], int | None]], interrupted: Callable[[int], int]
) -> int:
    """Runs a console script: handlers first, then the imports and the work, then a quick exit.

    Args:
        load: Imports the script's modules and returns its main function (exit code out).
        interrupted: The exit code for an interrupt that reached this level (one that came
            during the imports, or one the main function let through), given the signal.

    Returns:
        The exit code.
    """
    interrupt_on_signals()
    try:
        code = int(load()() or 0)
    except KeyboardInterrupt as exc:
        code = interrupted(signal_number(exc))
    # The work is over: a further signal ends the process at once, whatever the shutdown does.
    interrupt_on_signals(signal.SIG_DFL)
    gc.freeze()
    return code
