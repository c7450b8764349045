"""``lumpbeam track SRC OUT``: the camera pipeline over recorded footage, offline.

Only argument parsing lives here; the vision core (and OpenCV) is imported when the command
runs, so ``lumpbeam --help`` stays fast.
"""

from __future__ import annotations

import argparse
import math
import sys
from typing import Any

from lumpbeam_ros.cli.output import write_json
from lumpbeam_ros.errors import LumpbeamError

_DESCRIPTION = """\
Tracks the tip in camera footage and writes OUT, a rosbag2 bag (MCAP) with /tip_pose.

SRC is one of:
  a rosbag2 folder     sensor_msgs/Image (mono8, mono16, bgr8, rgb8, bayer_rggb8, bayer_bggr8,
                       bayer_gbrg8, bayer_grbg8) or sensor_msgs/CompressedImage (jpeg, png)
                       on --image-topic (default /camera/image_raw, else
                       /camera/image_raw/compressed); stamps from the messages, intrinsics
                       from --camera-info-topic. OUT is a copy of it plus /tip_pose (a
                       /tip_pose already there is replaced).
  a video file         anything OpenCV reads (avi, mkv, mp4, ...); needs --fps or --timestamps.
  a folder of images   png, jpg, tif, bmp, pgm, ppm, read in file-name order (zero-pad the
                       numbers); needs --fps or --timestamps.
For a video or a folder, OUT holds /tip_pose and /camera/camera_info, and the intrinsics come
from --camera-info.

Stamps: --fps HZ stamps frame i at START + i / HZ (START from --start-time, default 0).
--timestamps FILE is plain text with one stamp per line in seconds (e.g. 12.005 or
1732000000.123456789), in frame order and increasing; blank lines and lines starting with #
are skipped; it needs at least as many stamps as there are frames.

--camera-info FILE is the ROS camera calibration YAML (what the ROS camera calibrator writes
and camera_info_manager reads: image_width, image_height, camera_name, camera_matrix,
distortion_model, distortion_coefficients, rectification_matrix, projection_matrix); with a
bag it replaces the bag's camera_info.

The board's pattern and square size come from --config (config/camera.yaml), and
--board / --square-m override them. A progress bar is drawn on stderr when it is a terminal.
"""


def register(subparsers: Any) -> None:
    """Adds the ``track`` subcommand."""
    parser = subparsers.add_parser(
        'track',
        help='track the tip in a bag, a video or an image folder, offline',
        description=_DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument('src', help='rosbag2 folder, video file, or folder of images')
    parser.add_argument('out', help='bag folder to create (must not exist)')
    parser.add_argument('--config', help='camera file (default: config/camera.yaml)')
    parser.add_argument(
        '--camera-info', metavar='FILE', help='ROS camera calibration YAML (the intrinsics)'
    )
    parser.add_argument(
        '--board', metavar='COLSxROWS', help="the board's inner corners, e.g. 8x6 (9 x 7 squares)"
    )
    parser.add_argument('--square-m', type=float, metavar='M', help='edge of one square, m')
    stamps = parser.add_mutually_exclusive_group()
    stamps.add_argument('--fps', type=float, metavar='HZ', help='frame rate of a video/folder')
    stamps.add_argument(
        '--timestamps', metavar='FILE', help='one stamp per frame, s, one per line'
    )
    parser.add_argument(
        '--start-time', type=float, default=0.0, metavar='S', help='stamp of frame 0 with --fps'
    )
    parser.add_argument(
        '--image-topic',
        help='image topic of a bag (default: /camera/image_raw, else .../compressed)',
    )
    parser.add_argument(
        '--camera-info-topic', default='/camera/camera_info', help='(/camera/camera_info)'
    )
    parser.add_argument('--quiet', action='store_true', help='no progress bar')
    parser.add_argument(
        '--pose-model',
        choices=('plane', 'free'),
        default='plane',
        help='plane: x, z, pitch in the plane of bending (default); free: the full 6-DoF pose '
        "(torsion, a handheld check; with identity extrinsics, the camera's pose in the "
        "board's frame)",
    )
    parser.add_argument('--json', metavar='FILE', help='also write the summary as JSON')
    parser.set_defaults(handler=run)


def summary_lines(summary: Any, src: str, out: str) -> list[str]:
    """The human summary of a :class:`~lumpbeam_ros.vision.offline.TrackSummary`."""
    lost = ', '.join(f'{k} {v}' for k, v in sorted(summary.lost_by_reason.items()))
    lines = [
        f'tracked {src} -> {out}: {summary.frames} frames, {summary.poses} poses, '
        f'{summary.lost} lost{f" ({lost})" if lost else ""}, {summary.fps:.0f} frames/s'
    ]
    if summary.replaced_poses:
        lines.append(f'  /tip_pose of {src} ({summary.replaced_poses} poses) replaced')
    if summary.skipped_topics:
        lines.append(f'  not copied (no type definition): {", ".join(summary.skipped_topics)}')
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
            from lumpbeam_ros.progress import Progress

            # A video that does not declare its length gets no bar (no end to measure by).
            enabled = False if self.quiet or total is None else None
            self.bar = Progress(total or 1, self.label, enabled=enabled)
        self.bar.tick()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def run(args: argparse.Namespace) -> int:
    """Tracks SRC into OUT and prints the summary."""
    from lumpbeam_ros.vision.camera_info_file import read_camera_info_file
    from lumpbeam_ros.vision.config import load_camera_config, parse_board, with_board
    from lumpbeam_ros.vision.offline import track_bag, track_footage
    from lumpbeam_ros.vision.sources import FrameStamps, is_bag, open_footage

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
                pose_model=args.pose_model,
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
                'z_rms_um': summary.z_rms_um,
                'z_bias_um': summary.z_bias_um,
                'pitch_rms_mrad': summary.pitch_rms_mrad,
            },
        )
    return 0
