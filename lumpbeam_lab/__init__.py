"""The lab: what proves the product, installed beside it but never imported by it.

- :mod:`lumpbeam_lab.bench`: ``lumpbeam bench``, every figure a ratio against a baseline run in
  the same process.
- :mod:`lumpbeam_lab.camera`: the camera's validation matrix, an independent ray-casting
  renderer and the tracker's accuracy scored against the simulated truth.
- :mod:`lumpbeam_lab.doctor`: the structural check of the MCAP files and bags our own writer
  makes (``lumpbeam doctor``).

The product (``lumpbeam_ros``: the core, the nodes, the demo) imports nothing from here; only
the commands that run the lab (``lumpbeam bench``, ``lumpbeam doctor``) do.
``test/test_layers.py`` holds it.
"""
