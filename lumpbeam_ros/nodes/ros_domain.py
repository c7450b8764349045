"""Private ROS 2 domains: a process claims a domain id that no other lumpbeam process holds.

A graph of its own (the demo, a benchmark, a test) needs a domain nobody else on the machine
publishes on, or two graphs started at once hear each other's topics. A claim is an abstract
Unix socket named after the domain (Linux): binding it fails while another process holds
it, and the kernel frees the name when its holder closes it or exits, a crash included, so
no stale lock outlives a process and nothing is written to disk. Where abstract sockets do
not exist the claim is not exclusive (the domain is still picked from a per-process start).
"""

from __future__ import annotations

import errno
import itertools
import os
import socket
from collections.abc import Sequence

from lumpbeam_ros.base.closing import ClosedOnExit
from lumpbeam_ros.base.errors import LumpbeamError

#: Fast DDS maps domain ids to UDP ports; 1..101 are valid on Linux for any number of
#: participants. 0 is left to the user's own graph.
PRIVATE_DOMAIN_IDS = range(1, 102)

_NAME_PREFIX = b'\0lumpbeam_ros.ros_domain.'
_calls = itertools.count()


class DomainClaim(ClosedOnExit):
    """A domain id held by this process until :meth:`release` (or the ``with`` block's end).

    Args:
        domain_id: The domain.
        lock: The bound socket that holds it, ``None`` when the platform cannot hold one.

    Attributes:
        domain_id: The domain.
    """

    def __init__(self, domain_id: int, lock: socket.socket | None):
        self.domain_id = domain_id
        self._lock = lock

    def release(self) -> None:
        """Frees the domain for other processes (again: no effect)."""
        if self._lock is not None:
            self._lock.close()
            self._lock = None

    close = release


def claim_domain_id(candidates: Sequence[int] = PRIVATE_DOMAIN_IDS) -> DomainClaim:
    """Claims the first free domain of ``candidates``, searched from a per-call start.

    The start moves with the process id and with every call, so consecutive graphs of one
    process, and processes started together, begin their search at different domains.

    Args:
        candidates: The domain ids to choose from.

    Returns:
        The claim; keep it until every participant of the graph is gone.

    Raises:
        LumpbeamError: Every candidate is held by another process.
    """
    if not candidates:
        raise LumpbeamError('no ROS domain id to choose from')
    start = os.getpid() * 7 + next(_calls)
    for offset in range(len(candidates)):
        domain_id = candidates[(start + offset) % len(candidates)]
        lock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            lock.bind(_NAME_PREFIX + str(domain_id).encode())
        except OSError as error:
            lock.close()
            if error.errno == errno.EADDRINUSE:
                continue  # another process holds it
            return DomainClaim(domain_id, None)  # no abstract sockets here
        return DomainClaim(domain_id, lock)
    raise LumpbeamError(
        f'every ROS domain id of {candidates[0]}..{candidates[-1]} is held by another process'
    )
