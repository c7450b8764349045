"""Real-time scheduling for a node that must keep pace with a camera on a busy machine.

Under Linux's fair scheduler a node that needs a third of a core at 180 frames a second
still waits behind every other runnable process at each frame (two busy loops beside the
graph kept the camera node in the run queue 9 to 14 s for 4.5 s of work over a run, and
its frame queue overflowed). A ``SCHED_FIFO`` thread runs as soon as it is woken, ahead of
all ordinary work, as ros2_control's controller manager runs its update loop
(``thread_priority``, 50 there). The kernel's real-time throttling still leaves ordinary
work 5 % of each second. It takes ``CAP_SYS_NICE`` or an ``rtprio`` limit (limits.conf);
without either the node says so and runs as before.
"""

from __future__ import annotations

import os

from lumpbeam_ros.base.schema import Bounds, ParameterSpec

#: The node parameter, declared once for every node that takes it.
REALTIME_PRIORITY = ParameterSpec(
    'realtime_priority',
    'int',
    0,
    "SCHED_FIFO priority of all the node's threads (the middleware's included), 1-99, so "
    'that other work on the machine cannot delay it (needs CAP_SYS_NICE or an rtprio limit; '
    'without, a warning); 0: the normal scheduler',
    bounds=Bounds(0, 99),
)


def set_realtime_priority(priority: int) -> str:
    """Puts every thread of this process on ``SCHED_FIFO`` at ``priority``.

    Threads started later by one of them inherit it.

    Args:
        priority: 1 to 99; 0 leaves the scheduling as it is.

    Returns:
        ``''``, or one line saying why it could not (the first refusal stops it).
    """
    if priority == 0:
        return ''
    return _set_every_thread('SCHED_FIFO', priority)


def set_normal_scheduling() -> str:
    """Puts every thread of this process back on the normal scheduler (``SCHED_OTHER``).

    Returns:
        ``''``, or one line saying why it could not.
    """
    return _set_every_thread('SCHED_OTHER', 0)


def _set_every_thread(policy: str, priority: int) -> str:
    setter = getattr(os, 'sched_setscheduler', None)
    if setter is None:
        return f'realtime_priority {priority}: no real-time scheduling on this system; ignored'
    try:
        threads = [int(tid) for tid in os.listdir('/proc/self/task')]
    except OSError:
        threads = [0]
    param = os.sched_param(priority)
    for tid in threads:
        try:
            setter(tid, getattr(os, policy), param)
        except ProcessLookupError:
            continue  # the thread ended meanwhile
        except PermissionError:
            return (
                f'realtime_priority {priority}: not permitted (needs CAP_SYS_NICE or an rtprio '
                'limit); running with the normal scheduler'
            )
        except OSError as exc:
            return (
                f'realtime_priority {priority}: {exc.strerror}; running with the normal scheduler'
            )
    return ''
