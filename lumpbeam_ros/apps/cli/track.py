"""``lumpbeam track SRC OUT``: the camera pipeline over recorded footage, offline.

Only argument parsing lives here; the vision core (and OpenCV) is imported when the command
runs, so ``lumpbeam --help`` stays fast.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

from lumpbeam_ros.apps.cli.output import write_json
from lumpbeam_ros.base.errors import LumpbeamError


def summary_lines(summary: Any, src: str, out: str) -> list[str]:
    """The human summary of a :class:`~lumpbeam_ros.core.vision.offline.TrackSummary`."""
    lost = ', '.join(f'{k} {v}' for k, v in sorted(summary.lost_by_reason.items()))
    lines = [
        f'tracked {src} -> {out}: {summary.frames} frames, {summary.poses} poses, '
        f'{summary.lost} lost{f" ({lost})" if lost else ""}, {summary.fps:.0f} frames/s'
    ]
    if summary.replaced_poses:
        lines.append(f'  /tip_pose of {src} ({summary.replaced_poses} poses) replaced')
    if summary.skipped_topics:
        lines.append(f'  not copied (no type definition): {", ".join(summary.skipped_topics)}')
    if summary.images_left_out:
        images = ', '.join(summary.images_left_out)
        lines.append(f'  not copied (images; --keep-images keeps them): {images}')
    if not math.isnan(summary.z_rms_um):
        lines.append(
            f'  vs /tip_pose_truth ({summary.compared} poses): z rms {summary.z_rms_um:.2f} um '
            f'(bias {summary.z_bias_um:.2f} um), pitch rms {summary.pitch_rms_mrad:.4f} mrad'
        )
    return lines


class _ProgressBar:
    """Adapts the core's progress callback to a bar, made once the total is known."""

    def __init__(self, label: str, quiet: bool):
        self.label = label
        self.quiet = quiet
        self.bar: Any = None

    def __call__(self, done: int, total: int | None) -> None:
        if self.bar is None:
            from lumpbeam_ros.base.progress import Progress

            # A video that does not declare its length gets no bar (no end to measure by).
            enabled = False if self.quiet or total is None else None
            self.bar = Progress(total or 1, self.label, enabled=enabled)
        self.bar.tick()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def run(args: argparse.Namespace) -> int:
    """Tracks SRC into OUT and prints the summary."""
    from lumpbeam_ros.core.bagio.writer import replace_bags
    from lumpbeam_ros.core.vision.camera_info_file import read_camera_info_file
    from lumpbeam_ros.core.vision.config import load_camera_config, parse_board, with_board
    from lumpbeam_ros.core.vision.offline import track_bag, track_footage
    from lumpbeam_ros.core.vision.sources import FrameStamps, is_bag, open_footage

    if args.force:
        if Path(args.out).resolve() == Path(args.src).resolve():
            raise LumpbeamError(f'--force would replace the source {args.src} with OUT')
        replace_bags(args.out)
    config = load_camera_config(args.config)
    board = None if args.board is None else parse_board(args.board)
    config = with_board(config, board, args.square_m)
    info = None if args.camera_info is None else read_camera_info_file(args.camera_info)
    progress = _ProgressBar('tracking', args.quiet)
    try:
        if is_bag(args.src):
            summary = track_bag(
                args.src, args.out, config, args.image_topic, args.camera_info_topic,
                camera_info=info, camera_info_source=args.camera_info or '', progress=progress,
                pose_model=args.pose_model, keep_images=args.keep_images,
            )  # fmt: skip
        else:
            stamps = None
            if args.timestamps is not None:
                stamps = FrameStamps.from_file(args.timestamps)
            elif args.fps is not None:
                stamps = FrameStamps.from_fps(args.fps, args.start_time)
            source = open_footage(args.src, stamps, '--fps HZ or --timestamps FILE')
            if info is None:
                raise LumpbeamError(
                    f'{args.src} has no camera_info: give --camera-info FILE (a ROS calibration)'
                )
            summary = track_footage(
                source, args.out, config, info, args.src, args.camera_info, source.total,
                progress, args.pose_model,
            )  # fmt: skip
    finally:
        progress.close()
    print('\n'.join(summary_lines(summary, args.src, args.out)))
    for status, where in sorted(summary.first_problems.items()):
        count = summary.lost_by_reason.get(status, 0)
        print(f'lumpbeam track: warning: {count} x {status}, first: {where}', file=sys.stderr)
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
                'images_left_out': summary.images_left_out,
                'z_rms_um': summary.z_rms_um,
                'z_bias_um': summary.z_bias_um,
                'pitch_rms_mrad': summary.pitch_rms_mrad,
            },
        )
    return 0
