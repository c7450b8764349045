"""``lumpbeam track BAG OUT``: the camera pipeline over a bag's images (SPEC section 5)."""

from __future__ import annotations

import argparse
import math

from lumpbeam_ros.cli.output import write_json
from lumpbeam_ros.vision.config import load_camera_config
from lumpbeam_ros.vision.offline import TrackSummary, track_bag


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
    summary = track_bag(args.bag, args.out, config, args.image_topic, args.camera_info_topic)
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
