"""The arguments of every ``lumpbeam`` subcommand, declared without importing what runs them.

``lumpbeam --help`` and ``lumpbeam COMMAND --help`` build these parsers only, so this module
imports nothing beyond the standard library and :mod:`lumpbeam_ros.cli.output`'s argument
types; the code a command runs is imported by :mod:`lumpbeam_ros.cli.main` once it is chosen.
Defaults that the core also declares (topic names, the simulated tracker) are repeated here
as literals so that help needs no numpy; test/cli/test_arguments.py checks that they agree.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from lumpbeam_ros.cli.output import non_negative_float, positive_float

Subparsers = argparse._SubParsersAction

POSE_TOPIC = '/tip_pose'
REFERENCE_TOPIC = '/tracker/point'
IMAGE_TOPIC = '/camera/image_raw'
CAMERA_INFO_TOPIC = '/camera/camera_info'

#: The simulated laser tracker's defaults (``synthetic.tracker.TrackerOptions``).
TRACKER_RATE_HZ = 1000.0
TRACKER_NOISE_M = 15e-6
TRACKER_CLOCK_OFFSET_S = 7.3e-3
TRACKER_POSE = (1.2, -3.0, 0.35, 4.0, -8.0, 100.0)

BEAM_CONFIG_HELP = 'beam parameter file (default: config/paper_beam.yaml)'


def add_reproduce(subparsers: Subparsers) -> argparse.ArgumentParser:
    """Declares ``lumpbeam reproduce``.

    Args:
        subparsers: The top-level parser's subcommands.

    Returns:
        The subcommand's parser.
    """
    parser = subparsers.add_parser(
        'reproduce', help="the paper's Tables B.1, B.2, frequencies and static deflections"
    )
    parser.add_argument('--config', help=BEAM_CONFIG_HELP)
    parser.add_argument('--json', metavar='FILE', help='write the results as JSON')
    return parser


def add_synth(subparsers: Subparsers) -> argparse.ArgumentParser:
    """Declares ``lumpbeam synth OUT``.

    Args:
        subparsers: The top-level parser's subcommands.

    Returns:
        The subcommand's parser.
    """
    parser = subparsers.add_parser('synth', help='write a synthetic drop-test bag')
    parser.add_argument('out', help='bag folder to create (must not exist)')
    parser.add_argument('--config', help=BEAM_CONFIG_HELP)
    parser.add_argument('--duration', type=positive_float, default=12.0, help='seconds (12)')
    parser.add_argument('--rate', type=positive_float, default=180.0, help='pose rate, Hz (180)')
    parser.add_argument(
        '--noise', type=non_negative_float, default=20e-6, help='pose noise sigma, m (20e-6)'
    )
    parser.add_argument('--seed', type=int, default=0, help='noise seed (0)')
    parser.add_argument(
        '--effect',
        action='append',
        default=[],
        metavar='NAME=VALUE',
        help='hide a physical effect of the diagnosis in the data (repeatable)',
    )
    tracker = parser.add_argument_group('reference sensor (/tracker/point)')
    tracker.add_argument(
        '--tracker', action='store_true', help='add a simulated laser tracker at the tip'
    )
    tracker.add_argument(
        '--tracker-rate', type=positive_float, default=TRACKER_RATE_HZ, help='Hz (1000)'
    )
    tracker.add_argument(
        '--tracker-noise',
        type=non_negative_float,
        default=TRACKER_NOISE_M,
        help='noise sigma per axis, m (15e-6)',
    )
    tracker.add_argument(
        '--tracker-offset',
        type=float,
        default=TRACKER_CLOCK_OFFSET_S,
        help='tracker clock minus true time, s (7.3e-3)',
    )
    tracker.add_argument(
        '--tracker-pose',
        type=tracker_pose,
        default=TRACKER_POSE,
        metavar='X,Y,Z,ROLL,PITCH,YAW',
        help='tracker frame in beam_base: m and extrinsic xyz degrees (1.2,-3,0.35,4,-8,100)',
    )
    tracker.add_argument(
        '--tracker-lever', type=float, default=0.0, help='reflector beyond the tip, m (0)'
    )
    parser.add_argument(
        '--images',
        action='store_true',
        help='also film the tip camera: /camera/image_raw (mono8) and /camera/camera_info',
    )
    parser.add_argument(
        '--image-size',
        default='2048x2048',
        metavar='WxH',
        help='image size with --images (2048x2048: 4 MB a frame, 8.6 GB for 12 s)',
    )
    parser.add_argument('--camera-config', help='camera file (default: config/camera.yaml)')
    return parser


def tracker_pose(text: str) -> tuple[float, ...]:
    """Argument type of ``--tracker-pose``: six comma-separated numbers.

    Args:
        text: The option's value.

    Returns:
        x, y, z (m), roll, pitch, yaw (degrees).

    Raises:
        argparse.ArgumentTypeError: Not six numbers.
    """
    try:
        values = tuple(float(v) for v in text.split(','))
    except ValueError:
        raise argparse.ArgumentTypeError(f'expected 6 numbers, got {text!r}') from None
    if len(values) != 6:
        raise argparse.ArgumentTypeError(f'expected 6 comma-separated numbers, got {text!r}')
    return values


def add_track(subparsers: Subparsers) -> argparse.ArgumentParser:
    """Declares ``lumpbeam track BAG OUT``.

    Args:
        subparsers: The top-level parser's subcommands.

    Returns:
        The subcommand's parser.
    """
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
    parser.add_argument('--json', metavar='FILE', help='also write the summary as JSON')
    return parser


def add_analyze(subparsers: Subparsers) -> argparse.ArgumentParser:
    """Declares ``lumpbeam analyze BAG``.

    Args:
        subparsers: The top-level parser's subcommands.

    Returns:
        The subcommand's parser.
    """
    parser = subparsers.add_parser('analyze', help='identify frequency, damping and stiffness')
    parser.add_argument('bag', help='rosbag2 folder with /tip_pose (and /tip_load)')
    parser.add_argument('--json', help='write the result as JSON to this file')
    parser.add_argument('--plots', help='write figures (PNG) into this folder')
    parser.add_argument('--config', help=BEAM_CONFIG_HELP)
    parser.add_argument(
        '--identifier-config', help='identifier parameter file (default: config/identifier.yaml)'
    )
    return parser


def add_diagnose(subparsers: Subparsers) -> argparse.ArgumentParser:
    """Declares ``lumpbeam diagnose BAG``.

    Args:
        subparsers: The top-level parser's subcommands.

    Returns:
        The subcommand's parser.
    """
    parser = subparsers.add_parser(
        'diagnose',
        help='find the effect the model misses, add it, show the gap shrink',
        description='Fits the nominal beam and each effect of the library to a drop-test '
        'bag (/tip_pose, /tip_load), names the missing effect (or none, or unexplained) and '
        'reports the gap between model and measurement before and after adding it.',
    )
    parser.add_argument('bag', help='bag folder with /tip_pose and /tip_load')
    parser.add_argument('--config', help='nominal beam file (default: config/paper_beam.yaml)')
    parser.add_argument('--json', metavar='FILE', help='write the result as JSON')
    parser.add_argument('--plots', metavar='DIR', help='write figures (PNG) to this folder')
    parser.add_argument(
        '--write-model', metavar='FILE', help='write the augmented beam parameter file'
    )
    return parser


def add_compare(subparsers: Subparsers) -> argparse.ArgumentParser:
    """Declares ``lumpbeam compare BAG``.

    Args:
        subparsers: The top-level parser's subcommands.

    Returns:
        The subcommand's parser.
    """
    parser = subparsers.add_parser(
        'compare',
        help='camera poses against a reference sensor (/tracker/point)',
        description='Aligns a reference sensor (a laser tracker on the tip) to the camera in '
        'time and space from the data alone, then reports their difference, the clock '
        'offset (tracker_stamp = camera_stamp + offset) and the frequency and damping '
        'identified from each.',
    )
    parser.add_argument('bag', help='bag folder with /tip_pose and /tracker/point')
    parser.add_argument('--json', metavar='FILE', help='write the result as JSON')
    parser.add_argument('--plots', metavar='DIR', help='write compare.png (Fig. B.8) here')
    parser.add_argument('--config', help=BEAM_CONFIG_HELP)
    parser.add_argument('--identifier-config', help='identifier parameter file')
    parser.add_argument(
        '--max-offset',
        type=positive_float,
        default=1.0,
        metavar='S',
        help='largest clock offset searched, s (1)',
    )
    parser.add_argument(
        '--max-gap',
        type=positive_float,
        metavar='S',
        help='longest reference dropout bridged, s (2.5 reference periods)',
    )
    parser.add_argument('--camera-topic', default=POSE_TOPIC)
    parser.add_argument('--reference-topic', default=REFERENCE_TOPIC)
    return parser


def add_record(subparsers: Subparsers) -> argparse.ArgumentParser:
    """Declares ``lumpbeam record OUT [TOPIC...] [--all]``.

    Args:
        subparsers: The top-level parser's subcommands.

    Returns:
        The subcommand's parser.
    """
    parser = subparsers.add_parser(
        'record',
        help='record topics from the live graph into a bag',
        description='Records topics into a new rosbag2 bag (MCAP, CDR). Stops on Ctrl-C, '
        'SIGTERM or after --duration; a killed recorder loses at most the last flush period.',
    )
    parser.add_argument('out', help='bag folder to create (never overwritten)')
    parser.add_argument('topics', nargs='*', metavar='TOPIC', help='topics to record')
    parser.add_argument('--all', action='store_true', help='record every topic that appears')
    parser.add_argument('--duration', type=positive_float, help='stop after this many seconds')
    parser.add_argument(
        '--flush-period',
        type=positive_float,
        default=0.5,
        help='longest time a message stays in memory, s (default 0.5)',
    )
    return parser


def add_play(subparsers: Subparsers) -> argparse.ArgumentParser:
    """Declares ``lumpbeam play BAG``.

    Args:
        subparsers: The top-level parser's subcommands.

    Returns:
        The subcommand's parser.
    """
    parser = subparsers.add_parser(
        'play',
        help='replay a bag into the live graph with /clock',
        description='Publishes a bag with its original relative timing and /clock '
        '(for nodes run with use_sim_time). Stops at the end, on Ctrl-C or on SIGTERM.',
    )
    parser.add_argument('bag', help='rosbag2 folder (MCAP)')
    parser.add_argument('--rate', type=positive_float, default=1.0, help='speed factor')
    parser.add_argument('--loop', action='store_true', help='start again at the end')
    parser.add_argument('--topics', nargs='+', metavar='TOPIC', help='only these topics')
    parser.add_argument(
        '--delay',
        type=positive_float,
        default=0.5,
        help='wait this long before the first message, for subscribers to connect (s)',
    )
    return parser


def add_bench(subparsers: Subparsers) -> argparse.ArgumentParser:
    """Declares ``lumpbeam bench``.

    Args:
        subparsers: The top-level parser's subcommands.

    Returns:
        The subcommand's parser.
    """
    parser = subparsers.add_parser('bench', help='speed benchmarks against same-run baselines')
    parser.add_argument(
        '--only', action='append', metavar='SUITE', help='run only this suite (repeatable)'
    )
    parser.add_argument('--quick', action='store_true', help='small inputs (a smoke test)')
    parser.add_argument('--json', metavar='FILE', help='write the results as JSON')
    return parser


def add_demo(subparsers: Subparsers) -> argparse.ArgumentParser:
    """Declares ``lumpbeam demo``.

    Args:
        subparsers: The top-level parser's subcommands.

    Returns:
        The subcommand's parser.
    """
    parser = subparsers.add_parser(
        'demo',
        help='the whole pipeline on the built-in synthetic experiment',
        description='Synthesizes a drop test, replays it through the live node graph '
        '(player, simulator, identifier, recorder as separate processes on a private ROS '
        'domain), analyzes the recording and draws measured against predicted.',
    )
    parser.add_argument('--out', type=Path, default=Path('results'), help='output folder')
    parser.add_argument(
        '--duration', type=positive_float, default=12.0, help='record length, s (default 12)'
    )
    parser.add_argument('--seed', type=int, default=0, help='seed of the pose noise')
    parser.add_argument(
        '--adopt', action='store_true', help='the simulator adopts the live identified values'
    )
    parser.add_argument('--domain-id', type=int, help='ROS domain (default: a random one)')
    parser.add_argument('--config', type=Path, help='beam parameter file')
    parser.add_argument('--json', type=Path, help='also write the summary here')
    parser.add_argument(
        '--image-size',
        default='640x480',
        metavar='WxH',
        help='synthetic camera frames, tracked by the camera node (default 640x480)',
    )
    parser.add_argument(
        '--no-images', action='store_true', help="play the bag's /tip_pose, no camera node"
    )
    parser.add_argument(
        '--effect',
        action='append',
        metavar='NAME=VALUE',
        help='effect hidden in the data for the diagnosis (repeatable; default '
        'sensor_latency=0.015); --effect none hides nothing',
    )
    return parser
