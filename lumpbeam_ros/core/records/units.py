"""The quantities a record may hold, their units, axes and default start (standard library only).

Declared here once for the importer (:mod:`~.to_bag`) and for the command line's help, which
must not load numpy.
"""

from __future__ import annotations

#: Standard gravity, m/s^2 (the unit ``g``).
STANDARD_GRAVITY = 9.80665
#: Each quantity's units and their factor to SI; the first is the default.
UNITS: dict[str, dict[str, float]] = {
    'displacement': {'m': 1.0, 'mm': 1e-3, 'um': 1e-6},
    'acceleration': {'m/s^2': 1.0, 'g': STANDARD_GRAVITY},
}
#: The axes a record may be measured along; the last is the default (the beam's vertical).
AXES = ('x', 'y', 'z')
#: Stamps start here unless told otherwise (a fixed epoch, so that two imports of one file
#: give the same bag).
DEFAULT_START = '2000-01-01T00:00:00Z'
