"""Tip-pose samples as the estimators take them, and their validation.

A :class:`PoseWindow` is what the identifier analyses: a tip series (stamps, vertical tip
position and tip pitch, doc/interfaces.md) and the ``/tip_load`` readings that fall in or just
before it.
:func:`clean_window` turns raw samples (a bag, a live buffer) into strictly increasing, finite
arrays (:func:`~lumpbeam_ros.core.bagio.tipseries.clean_tip_series`) and counts what it dropped, so
a bad sample never becomes an exception in a live node.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.bagio.tipseries import (
    HoldsTipSeries,
    LoadSeries,
    SampleCounts,
    TipSeries,
    clean_tip_series,
)


@dataclass(frozen=True)
class PoseWindow(HoldsTipSeries):
    """Tip poses in frame ``beam_base`` over a stretch of time, with their load readings.

    Attributes:
        poses: The tip series (stamps strictly increasing after :func:`clean_window`).
        loads: ``/tip_load`` readings in the window (and the last one before it), if any.
        counts: What validation removed.
    """

    poses: TipSeries
    loads: LoadSeries = field(default_factory=LoadSeries)
    counts: SampleCounts = field(default_factory=SampleCounts)


def _as_1d(name: str, values: object) -> np.ndarray:
    try:
        array = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise LumpbeamError(f'{name}: expected numbers') from None
    if array.ndim != 1:
        raise LumpbeamError(f'{name}: expected a 1-D sequence, got shape {array.shape}')
    return array


def clean_loads(t: object, kg: object) -> LoadSeries:
    """Validates ``/tip_load`` readings: drops non-finite ones, sorts, keeps the last per stamp.

    Args:
        t: Stamps, s.
        kg: Mass at the tip, kg.

    Returns:
        The readings, increasing in time.

    Raises:
        LumpbeamError: The arrays are not 1-D or differ in length.
    """
    t_arr, kg_arr = _as_1d('load stamps', t), _as_1d('load masses', kg)
    if t_arr.size != kg_arr.size:
        raise LumpbeamError(f'load readings: {t_arr.size} stamps but {kg_arr.size} masses')
    keep = np.isfinite(t_arr) & np.isfinite(kg_arr)
    t_arr, kg_arr = t_arr[keep], kg_arr[keep]
    order = np.argsort(t_arr, kind='stable')
    t_arr, kg_arr = t_arr[order], kg_arr[order]
    # The later reading of a stamp wins: it is the one the experiment published last.
    last = np.ones(t_arr.size, dtype=bool)
    last[:-1] = np.diff(t_arr) > 0.0
    return LoadSeries(t_arr[last], kg_arr[last])


def clean_window(
    t: object,
    z: object,
    pitch: object | None = None,
    loads: LoadSeries | None = None,
    *,
    x: object | None = None,
) -> PoseWindow:
    """Validates tip-pose samples.

    Non-finite samples are dropped, stamps sorted, and of several samples with one stamp the
    first is kept. Gaps are left as they are: the estimators work on uneven stamps.

    Args:
        t: Stamps, s.
        z: Vertical tip positions, m.
        pitch: Tip pitches, rad; ``None`` fills NaN (the pitch cross-check is then skipped).
        loads: ``/tip_load`` readings, if any.
        x: Tip positions along the beam, m; ``None`` fills NaN (the estimators do not use
            them).

    Returns:
        The cleaned window, with the counts of what was removed.

    Raises:
        LumpbeamError: The arrays are not 1-D numbers or differ in length.
    """
    t_arr, z_arr = _as_1d('stamps', t), _as_1d('z', z)
    p_arr = np.full(t_arr.size, np.nan) if pitch is None else _as_1d('pitch', pitch)
    x_arr = np.full(t_arr.size, np.nan) if x is None else _as_1d('x', x)
    if not t_arr.size == z_arr.size == p_arr.size:
        raise LumpbeamError(
            f'pose samples: {t_arr.size} stamps, {z_arr.size} z and {p_arr.size} pitch values'
        )
    if x_arr.size != t_arr.size:
        raise LumpbeamError(f'pose samples: {t_arr.size} stamps but {x_arr.size} x values')
    poses, counts = clean_tip_series(
        TipSeries(t_arr, x_arr, z_arr, p_arr), pitch_required=pitch is not None
    )
    return PoseWindow(poses, loads or LoadSeries(), counts)
