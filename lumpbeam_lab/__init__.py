"""The lab: what proves the product, kept in the repository and not installed with it.

- :mod:`lumpbeam_lab.bench`: ``lumpbeam bench``, every figure a ratio against a baseline run in
  the same process.
- :mod:`lumpbeam_lab.camera`: the camera's validation matrix, an independent ray-casting
  renderer and the tracker's accuracy scored against the simulated truth.
- :mod:`lumpbeam_lab.ident`: the identifier's accuracy against peers (SSI-cov, ERA).
- :mod:`lumpbeam_lab.mujoco_arm`: the arm as MuJoCo models it, the independent check of ours.
- :mod:`lumpbeam_lab.arm_links` and :mod:`lumpbeam_lab.shaping_loop`: the arm's links learned
  from data and the shaping loop, scored against truth.

The product (``lumpbeam_ros``) never imports anything from here; ``lumpbeam bench`` finds the
lab in the checkout at run time (``test/test_layers.py`` holds it).
"""
