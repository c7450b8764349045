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
"""
