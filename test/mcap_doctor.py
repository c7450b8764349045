"""The MCAP doctor as a fixture: every bag the product writes must pass it clean.

The mcap CLI's ``doctor`` cannot be installed from the package registries here, so the
checks it makes (magic, record framing, chunk CRCs and time ranges, log-time order, message
and chunk indexes, statistics, metadata.yaml counts) are made by
:mod:`lumpbeam_ros.core.bagio.check`, the product's own implementation of them.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from lumpbeam_ros.core.bagio.check import examine_bag


@pytest.fixture(scope='session')
def mcap_doctor() -> Callable[[Path], str]:
    """A function that examines a bag and returns its problems, one per line ('' if none)."""
    return lambda bag: '\n'.join(examine_bag(bag))
