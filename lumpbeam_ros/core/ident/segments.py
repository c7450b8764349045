"""Gaps and jumps in the pose stamps: the record split, the stretch with the release kept.

A bag whose clock jumped (a recorder restarted, a replay looped, a stamp corrupted) holds
stretches that do not belong to one experiment; analysed as one they give wrong estimates
and, over a jump of 1e6 s, arrays sized by the jump. Every gap longer than
``window.max_gap_s`` splits the window; the last stretch in which a release is found is
kept (else the longest), and the split is named.
"""

from __future__ import annotations

import numpy as np

from lumpbeam_ros.core.ident.release import detect_release
from lumpbeam_ros.core.ident.samples import PoseWindow
from lumpbeam_ros.core.ident.settings import IdentifierConfig


def keep_release_segment(window: PoseWindow, config: IdentifierConfig) -> tuple[PoseWindow, str]:
    """Splits a window at its stamp gaps and keeps the stretch holding the release.

    Args:
        window: Cleaned poses (stamps increasing).
        config: ``max_gap_s`` and the release detection's settings.

    Returns:
        The kept stretch (``window`` itself when there is no gap) and a note naming the
        gaps and what was dropped (``''`` when nothing was).
    """
    t = window.t
    gaps = np.flatnonzero(np.diff(t) > config.max_gap_s)
    if gaps.size == 0:
        return window, ''
    bounds = [0, *(gaps + 1).tolist(), t.size]
    parts = [
        PoseWindow(
            window.poses.select(slice(a, b)),
            window.loads.between(t[a], t[b - 1]),
            window.counts,
        )
        for a, b in zip(bounds[:-1], bounds[1:], strict=True)
    ]
    with_release = [p for p in parts if len(p) > 1 and detect_release(p, config).found]
    kept = with_release[-1] if with_release else max(parts, key=len)
    jumps = ', '.join(f'by {t[g + 1] - t[g]:+.6g} s after {t[g]:.3f} s' for g in gaps)
    why = 'the release' if with_release else 'the most poses'
    note = (
        f'stamps jump {jumps}: kept {kept.start_s:.3f} to {kept.end_s:.3f} s ({len(kept)} '
        f'poses, {why}), dropped {len(window) - len(kept)} poses in {len(parts) - 1} other '
        f'stretch{"es" if len(parts) > 2 else ""}'
    )
    return kept, note
