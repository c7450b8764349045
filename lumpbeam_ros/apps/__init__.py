"""What a user runs: the ``lumpbeam`` command line, the demo, campaigns and reports.

Listed in :data:`__all__` from the bottom up: :mod:`~.json_output` (the ``--json`` files),
:mod:`~.plots` (figures), :mod:`~.report` (HTML reports), :mod:`~.campaign` (many bags on
Dask), :mod:`~.demo` (the live pipeline) and :mod:`~.cli` (the commands).
"""

#: :data:`__all__` lists the packages bottom first: each imports only those before it.
LAYERED = True

__all__ = [
    'json_output',
    'plots',
    'report',
    'campaign',
    'demo',
    'cli',
]
