"""Self-contained HTML reports (``--report FILE.html``): figures embedded, no network needed.

:mod:`~lumpbeam_ros.report.html` builds the page; one module per command fills it.
"""
