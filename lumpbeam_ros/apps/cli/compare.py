"""``lumpbeam compare BAG``: camera poses against a reference sensor (doc/interfaces.md)."""

from __future__ import annotations

import argparse
import math

import numpy as np
from scipy.spatial.transform import Rotation

from lumpbeam_ros.apps.cli.output import write_json
from lumpbeam_ros.core.compare.align import AlignOptions
from lumpbeam_ros.core.compare.bag_comparison import (
    LOAD_TOPIC,
    read_comparison_input,
)
from lumpbeam_ros.core.compare.comparison import Comparison, compare_sensors
from lumpbeam_ros.core.ident.identification import Identification
from lumpbeam_ros.core.ident.settings import load_identifier_config
from lumpbeam_ros.core.model.parameters import load_beam_config


def run(args: argparse.Namespace) -> int:
    """Reads the bag, compares, prints the summary, writes JSON and the figure."""
    beam, _ = load_beam_config(args.config)
    config = load_identifier_config(args.identifier_config)
    streams = read_comparison_input(args.bag, args.camera_topic, args.reference_topic, LOAD_TOPIC)
    comparison = compare_sensors(
        streams.camera,
        streams.reference,
        beam,
        streams.loads,
        AlignOptions(max_offset_s=args.max_offset, max_gap_s=args.max_gap),
        config,
    )
    print(summary(comparison))
    if args.json:
        write_json(args.json, comparison.as_dict())
    if args.plots:
        from lumpbeam_ros.apps.plots.comparison import plot_comparison  # matplotlib only if asked

        print(f'figure: {plot_comparison(comparison, args.plots)}')
    if args.report:
        from lumpbeam_ros.apps.report.comparison import write_comparison_report

        print(f'report: {write_comparison_report(comparison, args.bag, args.report)}')
    return 0


def summary(comparison: Comparison) -> str:
    """The human-readable result: alignment, differences, both identifications."""
    aligned = comparison.aligned
    alignment = aligned.alignment
    track = aligned.reference.track
    transform = alignment.transform
    angles = Rotation.from_matrix(transform.rotation).as_euler('xyz', degrees=True)
    rot_std = np.degrees(alignment.rotation_std_rad)
    lines = [
        f'reference: {track.source} ({len(track)} points, frame {track.frame_id!r}, '
        f'{aligned.reference.gap_count} gaps), '
        f'{comparison.t.size} camera samples compared',
        f'time offset: tracker_stamp = camera_stamp + {alignment.offset_s * 1e3:.4f} '
        f'+- {alignment.offset_std_s * 1e3:.4f} ms '
        f'(cross-correlation {aligned.coarse.offset_s * 1e3:.3f} ms, r = '
        f'{aligned.coarse.correlation:+.4f}; segments agree to '
        f'{alignment.offset_consistency:.2f} x their noise)',
        'tracker -> beam_base: translation '
        + _vector(transform.translation, alignment.translation_std_m, 1e3, 'mm')
        + ', rotation xyz '
        + _vector(angles, rot_std, 1.0, 'deg'),
        f'difference after alignment (camera - tracker, z): RMS '
        f'{comparison.rms_difference_m * 1e6:.1f} um, max {comparison.max_difference_m * 1e6:.1f} '
        f'um; tracker off the motion plane: RMS {alignment.plane_rms_m * 1e6:.1f} um',
        f'{"":24s}{"camera":>24s}{"tracker":>24s}',
    ]
    rows = (
        ('status', 'status', 1.0, ''),
        ('natural frequency [Hz]', 'natural_frequency_hz', 1.0, '.5f'),
        ('damping ratio', 'damping_ratio', 1.0, '.5f'),
        ('release [s]', 'release_time_s', 1.0, '.4f'),
        ('static deflection [mm]', 'static_deflection_m', 1e3, '.3f'),
    )
    results = [comparison.per_sensor['camera'], comparison.per_sensor['tracker']]
    for label, key, scale, spec in rows:
        cells = [_cell(ident, key, scale, spec) for ident in results]
        lines.append(f'{label:24s}{cells[0]:>24s}{cells[1]:>24s}')
    return '\n'.join(lines)


def _vector(values: np.ndarray, stds: np.ndarray, scale: float, unit: str) -> str:
    parts = ', '.join(f'{v * scale:.3f}' for v in values)
    errors = ', '.join(f'{s * scale:.2g}' for s in stds)
    return f'({parts}) +- ({errors}) {unit}'


def _cell(ident: Identification, key: str, scale: float, spec: str) -> str:
    if key == 'status':
        return ident.status.name
    value, std = ident.figure(key).value, ident.figure(key).std
    if not math.isfinite(value):
        return 'n/a'
    text = f'{value * scale:{spec}}'
    if math.isfinite(std):
        text += f' +- {std * scale:.2g}'
    return text
