"""Camera poses against a reference sensor (``lumpbeam compare``, the paper's Fig. B.8).

A laser tracker (or any second sensor at the tip) publishes ``/tracker/point`` in its own
frame and on its own clock. From the data alone this package finds the clock offset
(``tracker_stamp = camera_stamp + offset``) and the rigid transform from the tracker frame to
``beam_base``, then reports how far the camera's tip displacement is from the tracker's and
what each sensor says about the beam's frequency and damping.

Modules, in the order they run: :mod:`~.streams` (cleaning, gap-aware interpolation),
:mod:`~.offset` (cross-correlation), :mod:`~.rigid` (Kabsch fit, observability),
:mod:`~.refine` (joint least squares), :mod:`~.align` (the three together),
:mod:`~.comparison` (differences and identification), :mod:`~.bag` (reading a bag).

Use::

    streams = read_comparison_input('bags/validation')
    result = compare_sensors(streams.camera, streams.reference, beam, streams.loads)
    result.as_dict()['time_offset_s']
"""

from lumpbeam_ros.core.compare.align import AlignedStreams, AlignOptions, align_streams
from lumpbeam_ros.core.compare.bag_comparison import ComparisonInput, read_comparison_input
from lumpbeam_ros.core.compare.comparison import Comparison, compare_sensors
from lumpbeam_ros.core.compare.refine import Alignment
from lumpbeam_ros.core.compare.rigid import fit_rigid
from lumpbeam_ros.core.compare.streams import GapInterpolator, Track, clean_track
from lumpbeam_ros.core.compare.transforms import RigidTransform

__all__ = [
    'AlignOptions',
    'AlignedStreams',
    'Alignment',
    'Comparison',
    'ComparisonInput',
    'GapInterpolator',
    'RigidTransform',
    'Track',
    'align_streams',
    'clean_track',
    'compare_sensors',
    'fit_rigid',
    'read_comparison_input',
]
