"""Campaigns: ``lumpbeam analyze`` (and ``diagnose``) over many bags on a Dask cluster.

- :mod:`~lumpbeam_ros.apps.campaign.bags`: which bags, and a content fingerprint of each;
- :mod:`~lumpbeam_ros.apps.campaign.task`: one bag's row (what a Dask worker runs);
- :mod:`~lumpbeam_ros.apps.campaign.store`: the results table, written atomically as it grows;
- :mod:`~lumpbeam_ros.apps.campaign.engine`: the cluster, the progress and the resume logic;
- :mod:`~lumpbeam_ros.apps.campaign.fit`: the beam's EI and mass fitted across the campaign.

Only :mod:`~lumpbeam_ros.apps.campaign.engine` imports Dask, and only the store imports pyarrow.
"""

__all__ = [
    'bags',
    'engine',
    'fit',
    'store',
    'summary',
    'task',
]
