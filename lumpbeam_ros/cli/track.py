"""``lumpbeam track BAG OUT``: the camera pipeline over a bag's images (SPEC section 5)."""

from __future__ import annotations

import argparse
import math
from typing import Any

from lumpbeam_ros.cli.output import write_json
from lumpbeam_ros.vision.config import load_camera_config
from lumpbeam_ros.vision.free_pose import POSE_MODELS
from lumpbeam_ros.vision.offline import CAMERA_INFO_TOPIC, IMAGE_TOPIC, TrackSummary, track_bag


def register(subparsers: Any) -> None:
    """Adds the ``track`` subcommand."""
    parser = subparsers.add_parser(
        'track',
        help="track the tip in a bag's images, offline",
        description='Writes OUT: a copy of BAG plus /tip_pose tracked from its images '
        '(a /tip_pose already in BAG is replaced).',
    )
    parser.add_argument('bag', help='rosbag2 folder (MCAP) with images and camera info')
    parser.add_argument('out', help='bag folder to create (must not exist)')
    parser.add_argument('--config', help='camera file (default: config/camera.yaml)')
    parser.add_argument('--image-topic', default=IMAGE_TOPIC, help=f'({IMAGE_TOPIC})')
    parser.add_argument(
        '--camera-info-topic', default=CAMERA_INFO_TOPIC, help=f'({CAMERA_INFO_TOPIC})'
    )
    parser.add_argument(
        '--pose-model',
        choices=POSE_MODELS,
        default='plane',
        help='plane: x, z, pitch in the plane of bending (default); free: the full 6-DoF pose '
        "(torsion, a handheld check; with identity extrinsics, the camera's pose in the "
        "board's frame)",
    )
    parser.add_argument('--json', metavar='FILE', help='also write the summary as JSON')
    parser.set_defaults(handler=run)


def summary_lines(summary: TrackSummary, bag: str, out: str) -> list[str]:
    """The human summary."""
    lost = ', '.join(f'{k} {v}' for k, v in sorted(summary.lost_by_reason.items()))
    lines = [
        f'tracked {bag} -> {out}: {summary.frames} frames, {summary.poses} poses, '
        f'{summary.lost} lost{f" ({lost})" if lost else ""}, {summary.fps:.0f} frames/s'
    ]
    if summary.replaced_poses:
        lines.append(f'  /tip_pose of {bag} ({summary.replaced_poses} poses) replaced')
    if summary.skipped_topics:
        lines.append(f'  not copied (no type definition): {", ".join(summary.skipped_topics)}')
    if not math.isnan(summary.z_rms_um):
        lines.append(
            f'  vs /tip_pose_truth ({summary.compared} poses): z rms {summary.z_rms_um:.2f} um '
            f'(bias {summary.z_bias_um:.2f} um), pitch rms {summary.pitch_rms_mrad:.4f} mrad'
        )
    return lines


def run(args: argparse.Namespace) -> int:
    """Tracks the bag and prints the summary."""
    config = load_camera_config(args.config)
    summary = track_bag(
        args.bag, args.out, config, args.image_topic, args.camera_info_topic, args.pose_model
    )
    print('\n'.join(summary_lines(summary, args.bag, args.out)))
    if args.json:
        write_json(
            args.json,
            {
                'frames': summary.frames,
                'poses': summary.poses,
                'lost': summary.lost,
                'lost_by_reason': summary.lost_by_reason,
                'fps': summary.fps,
                'replaced_poses': summary.replaced_poses,
                'skipped_topics': summary.skipped_topics,
                'z_rms_um': summary.z_rms_um,
                'z_bias_um': summary.z_bias_um,
                'pitch_rms_mrad': summary.pitch_rms_mrad,
            },
        )
    return 0
