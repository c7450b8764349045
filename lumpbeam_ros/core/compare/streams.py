"""The two position streams a comparison takes, and gap-aware interpolation of the reference.

A :class:`Track` is one sensor's point positions over its own clock: the camera's tip
positions in ``beam_base`` (``y = 0``: the motion is planar, doc/interfaces.md) or the tracker's
retroreflector positions in the tracker's frame. :class:`GapInterpolator` reads the fast
reference stream at arbitrary times and says where it cannot: outside its span and inside
dropouts, where a straight line between the samples around the gap would be a guess.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError

#: Fewest valid samples a stream needs to take part in a comparison.
MIN_SAMPLES = 20

#: A spacing above this many median sample periods is a dropout, not a late sample.
GAP_FACTOR = 2.5


@dataclass(frozen=True)
class Track:
    """Positions of one sensor, cleaned: finite, stamps strictly increasing.

    Attributes:
        t: Stamps on the sensor's own clock, s.
        points: Positions, ``(n, 3)``, m, in ``frame_id``.
        frame_id: The frame of ``points``.
        source: Where the samples came from (a topic), for messages.
        pitch: Tip pitch per sample, rad (NaN when the sensor has none).
    """

    t: np.ndarray
    points: np.ndarray
    frame_id: str
    source: str
    pitch: np.ndarray

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def period_s(self) -> float:
        """Median sample spacing, s."""
        return float(np.median(np.diff(self.t)))

    @property
    def span(self) -> tuple[float, float]:
        """First and last stamp, s."""
        return float(self.t[0]), float(self.t[-1])


def clean_track(
    t: object,
    points: object,
    frame_id: str,
    source: str,
    pitch: object | None = None,
) -> Track:
    """Validates one sensor's samples.

    Non-finite samples are dropped, the stamps sorted, and of several samples with one stamp
    the first is kept: a recorder may log a message twice, and the first is the one sent.

    Args:
        t: Stamps, s.
        points: Positions, ``(n, 3)``, m.
        frame_id: Their frame.
        source: The topic (or other origin), for messages.
        pitch: Tip pitch, rad, or ``None``.

    Returns:
        The cleaned track.

    Raises:
        LumpbeamError: Shapes do not match, or fewer than :data:`MIN_SAMPLES` valid samples.
    """
    t_arr = np.asarray(t, dtype=float).reshape(-1)
    p_arr = np.asarray(points, dtype=float)
    if p_arr.ndim != 2 or p_arr.shape != (t_arr.size, 3):
        raise LumpbeamError(f'{source}: expected {t_arr.size} x 3 positions, got {p_arr.shape}')
    pitch_arr = (
        np.full(t_arr.size, np.nan) if pitch is None else np.asarray(pitch, float).reshape(-1)
    )
    if pitch_arr.size != t_arr.size:
        raise LumpbeamError(f'{source}: {t_arr.size} stamps but {pitch_arr.size} pitches')
    keep = np.isfinite(t_arr) & np.all(np.isfinite(p_arr), axis=1)
    order = np.argsort(t_arr[keep], kind='stable')
    t_arr, p_arr, pitch_arr = t_arr[keep][order], p_arr[keep][order], pitch_arr[keep][order]
    first = np.ones(t_arr.size, dtype=bool)
    first[1:] = np.diff(t_arr) > 0.0
    t_arr, p_arr, pitch_arr = t_arr[first], p_arr[first], pitch_arr[first]
    if t_arr.size < MIN_SAMPLES:
        raise LumpbeamError(
            f'{source}: {t_arr.size} valid samples, need at least {MIN_SAMPLES} to compare'
        )
    return Track(t_arr, p_arr, frame_id, source, pitch_arr)


class GapInterpolator:
    """Linear interpolation of a track, with the stretches where it is not to be trusted.

    At 1 kHz and 3 Hz, the chord between samples misses a sine of 40 mm by under 1 um, far
    below the sensors' noise, so linear interpolation is exact enough and cannot ring.

    Args:
        track: The stream to read (the fast reference).
        max_gap_s: Longest spacing still bridged; default :data:`GAP_FACTOR` median periods.
    """

    def __init__(self, track: Track, max_gap_s: float | None = None):
        self.track = track
        self.max_gap_s = GAP_FACTOR * track.period_s if max_gap_s is None else max_gap_s
        spacing = np.diff(track.t)
        gap = np.flatnonzero(spacing > self.max_gap_s)
        self.gap_starts = track.t[gap]
        self.gap_ends = track.t[gap + 1]

    @property
    def gap_count(self) -> int:
        """Number of dropouts longer than ``max_gap_s``."""
        return int(self.gap_starts.size)

    def valid(self, query: np.ndarray, margin_s: float = 0.0) -> np.ndarray:
        """Whether each time is inside the track and at least ``margin_s`` from any dropout.

        Args:
            query: Times on the track's clock, s.
            margin_s: Distance to keep from the ends and from the edges of gaps, s.

        Returns:
            A boolean mask like ``query``.
        """
        query = np.asarray(query, dtype=float)
        start, end = self.track.span
        ok = (query >= start + margin_s) & (query <= end - margin_s)
        if self.gap_count:
            # Gaps are sorted and disjoint: the last one starting before a time is the only
            # one that can contain it.
            index = np.searchsorted(self.gap_starts - margin_s, query, side='right') - 1
            inside = (index >= 0) & (query < self.gap_ends[np.maximum(index, 0)] + margin_s)
            ok &= ~inside
        return ok

    def __call__(self, query: np.ndarray) -> np.ndarray:
        """Positions at ``query``, ``(n, 3)``; check :meth:`valid` first."""
        t, points = self.track.t, self.track.points
        return np.column_stack([np.interp(query, t, points[:, i]) for i in range(3)])

    def scalar(self, values: np.ndarray, query: np.ndarray) -> np.ndarray:
        """Interpolates a per-sample scalar of the track (e.g. a projection) at ``query``."""
        return np.asarray(np.interp(query, self.track.t, values))

    def velocity(self, query: np.ndarray, half_width_s: float) -> np.ndarray:
        """Central-difference velocity over ``+- half_width_s``, ``(n, 3)``, m/s."""
        ahead = self(query + half_width_s)
        behind = self(query - half_width_s)
        return np.asarray((ahead - behind) / (2.0 * half_width_s))
