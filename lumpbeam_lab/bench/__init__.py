"""Benchmarks: every figure is a ratio against a baseline measured in the same run.

A suite is a module in this package with ``run(quick: bool) -> list[BenchResult]``; the
runner (:mod:`lumpbeam_lab.bench.runner`) lists them in ``SUITES``.
"""
