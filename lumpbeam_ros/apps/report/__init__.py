"""Self-contained HTML reports (``--report FILE.html``): figures embedded, no network needed.

:mod:`~lumpbeam_ros.apps.report.html` builds the page; one module per command fills it.
"""

__all__ = [
    'analysis',
    'comparison',
    'diagnosis',
    'html',
]
