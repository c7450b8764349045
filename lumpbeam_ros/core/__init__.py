"""The domain: the lumped model and everything computed from it or measured against it.

ROS-free: numpy arrays, dataclasses and paths in, the same out. The packages are listed in
:data:`__all__` from the bottom up; each imports only those before it
(``test/test_layers.py``):

- :mod:`~.bagio`: rosbag2/MCAP bags, read and written, and messages as numpy;
- :mod:`~.records`: a lab's measurement files (LabVIEW, CSV, NumPy, MATLAB) read, and
  written as bags;
- :mod:`~.model`: the lumped beam (B.14-B.18), its statics, modes and simulation, the
  physical effects; :mod:`~.model.arm`: the flexible arm and the joint motion that drives it;
- :mod:`~.ident`: stiffness, frequency and damping from the vibration (B.12-B.22);
  :mod:`~.ident.arm`: an arm's moves, ring-downs and links from data;
- :mod:`~.shaping`: input shapers and the commands they shape;
- :mod:`~.diagnose`: the model-discrepancy workflow;
- :mod:`~.compare`: the camera against a reference sensor;
- :mod:`~.viz`: what a viewer draws (markers, layouts);
- :mod:`~.vision`: the checkerboard, the camera and the tip tracker;
- :mod:`~.synthetic`: the experiments simulated into bags.
"""

#: :data:`__all__` lists the packages bottom first: each imports only those before it.
LAYERED = True

__all__ = [
    'bagio',
    'records',
    'model',
    'ident',
    'shaping',
    'diagnose',
    'compare',
    'viz',
    'vision',
    'synthetic',
]
