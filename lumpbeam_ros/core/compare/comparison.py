"""Camera against reference sensor: differences after alignment, and both identifications.

This is the validation of the paper's Fig. B.8: the camera's tip displacement beside a laser
tracker's, once the two are brought into one frame and onto one clock, and the frequency and
damping each sensor yields on its own (section B.3.2, via
:func:`~lumpbeam_ros.core.ident.identify`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from lumpbeam_ros.base.interface import BASE_FRAME
from lumpbeam_ros.core.bagio.tipseries import LoadSeries
from lumpbeam_ros.core.compare.align import AlignedStreams, AlignOptions, align_streams
from lumpbeam_ros.core.compare.streams import Track
from lumpbeam_ros.core.ident.identification import Identification
from lumpbeam_ros.core.ident.identify import identify
from lumpbeam_ros.core.ident.samples import clean_window
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.model.parameters import BeamParameters

AXES = ('x', 'y', 'z')


@dataclass(frozen=True)
class Comparison:
    """The outcome of :func:`compare_sensors`.

    Attributes:
        aligned: Offset and transform, with the coarse estimate and the interpolated
            reference.
        t: Camera stamps of the compared pairs, s (camera clock).
        camera: Camera positions at ``t``, ``(n, 3)``, ``beam_base``.
        reference: Reference positions at the same instants, ``(n, 3)``, ``beam_base``.
        reference_t: Every reference stamp moved onto the camera clock, s.
        reference_points: Every reference position in ``beam_base``, ``(m, 3)``.
        per_sensor: ``{'camera': ..., 'tracker': ...}`` identifications.
    """

    aligned: AlignedStreams
    t: np.ndarray
    camera: np.ndarray
    reference: np.ndarray
    reference_t: np.ndarray
    reference_points: np.ndarray
    per_sensor: dict[str, Identification]

    @property
    def difference(self) -> np.ndarray:
        """Camera minus reference at each pair, ``(n, 3)``, m."""
        return np.asarray(self.camera - self.reference)

    @property
    def rms_difference_m(self) -> float:
        """RMS of the vertical tip displacement difference (the quantity of Fig. B.8), m."""
        return float(np.sqrt(np.mean(self.difference[:, 2] ** 2)))

    @property
    def max_difference_m(self) -> float:
        """Largest absolute vertical displacement difference, m."""
        return float(np.max(np.abs(self.difference[:, 2])))

    def as_dict(self) -> dict[str, Any]:
        """The machine-readable result (``lumpbeam compare --json``).

        ``time_offset_s`` follows ``tracker_stamp = camera_stamp + time_offset_s``; the
        transform maps tracker coordinates into ``beam_base``
        (``p_beam = R p_tracker + t``: the tracker frame's pose in ``beam_base``).
        """
        alignment = self.aligned.alignment
        transform = alignment.transform
        rms_axes = np.sqrt(np.mean(self.difference**2, axis=0))
        return {
            'time_offset_s': alignment.offset_s,
            'time_offset_s_std': alignment.offset_std_s,
            'time_offset_s_std_white': alignment.offset_std_white_s,
            'time_offset_consistency': alignment.offset_consistency,
            'time_offset_convention': 'tracker_stamp = camera_stamp + time_offset_s',
            'rms_difference_m': self.rms_difference_m,
            'max_difference_m': self.max_difference_m,
            'rms_difference_by_axis_m': dict(zip(AXES, rms_axes.tolist(), strict=True)),
            'pairs': int(self.t.size),
            'reference_samples': int(self.reference_t.size),
            'reference_gaps': self.aligned.reference.gap_count,
            'coarse_time_offset_s': self.aligned.coarse.offset_s,
            'correlation': self.aligned.coarse.correlation,
            'transform': {
                'parent_frame': BASE_FRAME,
                'child_frame': self.aligned.reference.track.frame_id,
                'rotation_matrix': transform.rotation.tolist(),
                'quaternion_xyzw': transform.quaternion_xyzw().tolist(),
                'translation_m': transform.translation.tolist(),
                'rotation_std_rad': alignment.rotation_std_rad.tolist(),
                'translation_std_m': alignment.translation_std_m.tolist(),
                'plane_rms_m': alignment.plane_rms_m,
            },
            'per_sensor': {name: ident.as_dict() for name, ident in self.per_sensor.items()},
        }


def compare_sensors(
    camera: Track,
    reference: Track,
    beam: BeamParameters,
    loads: LoadSeries | None = None,
    options: AlignOptions | None = None,
    config: IdentifierConfig | None = None,
) -> Comparison:
    """Aligns the reference to the camera, takes the differences, identifies from each.

    Args:
        camera: Camera tip positions in ``beam_base`` (with pitch).
        reference: Reference positions in its own frame and clock.
        beam: The beam, for the identification's stiffness (B.12).
        loads: ``/tip_load`` readings on the camera clock, if any.
        options: Alignment search settings.
        config: Identifier settings.

    Returns:
        The comparison.

    Raises:
        LumpbeamError: The streams cannot be aligned (see :func:`~.align.align_streams`).
    """
    aligned = align_streams(camera, reference, options)
    alignment = aligned.alignment
    pairs = alignment.pairs
    t = camera.t[pairs]
    matched = alignment.transform.apply(aligned.reference(t + alignment.offset_s))
    reference_t = reference.t - alignment.offset_s
    reference_points = alignment.transform.apply(reference.points)
    per_sensor = {
        'camera': identify(
            clean_window(camera.t, camera.points[:, 2], camera.pitch, loads), beam, config
        ),
        'tracker': identify(
            clean_window(reference_t, reference_points[:, 2], None, loads), beam, config
        ),
    }
    return Comparison(
        aligned=aligned,
        t=t,
        camera=camera.points[pairs],
        reference=matched,
        reference_t=reference_t,
        reference_points=reference_points,
        per_sensor=per_sensor,
    )
