"""The arguments of every ``lumpbeam`` subcommand, declared without importing what runs them.

``lumpbeam --help`` and ``lumpbeam COMMAND --help`` build these parsers only, so this module
imports nothing beyond the standard library and :mod:`lumpbeam_ros.apps.cli.output`'s argument
types; the code a command runs is imported by :mod:`lumpbeam_ros.apps.cli.main` once it is chosen.
Defaults that the core also declares (topic names, the simulated tracker) are repeated here
as literals so that help needs no numpy; test/apps/cli/test_arguments.py checks that they agree.
"""

from __future__ import annotations

import argparse
import functools
from collections.abc import Callable
from pathlib import Path
from typing import Any

from lumpbeam_ros.apps.cli.output import non_negative_float, positive_float, positive_int
from lumpbeam_ros.base.interface import CAMERA_INFO, TIP_POSE, TRACKER_POINT
from lumpbeam_ros.core.records.units import AXES, DEFAULT_START, UNITS
from lumpbeam_ros.core.shaping.choices import DEFAULT_MAX_MODES, SHAPER_NAMES

Subparsers = argparse._SubParsersAction

#: Adds a subcommand to the top-level parser and returns the subcommand's parser.
Declare = Callable[[Subparsers], argparse.ArgumentParser]


class IntermixedParser(argparse.ArgumentParser):
    """A subcommand's parser that takes positional arguments before, between and after options.

    ``lumpbeam record OUT --duration 1 /tip_pose``: the plain parser assigns every positional
    at its first run of them (``TOPIC...`` gets none) and then refuses ``/tip_pose``.
    """

    _intermixing = False

    def parse_known_args(  # type: ignore[override]
        self, args: Any = None, namespace: Any = None
    ) -> tuple[argparse.Namespace, list[str]]:
        """Parses as :meth:`argparse.ArgumentParser.parse_known_intermixed_args` does."""
        if self._intermixing:  # its own passes call this method again
            return super().parse_known_args(args, namespace)
        self._intermixing = True
        try:
            return self.parse_known_intermixed_args(args, namespace)
        finally:
            self._intermixing = False


def _subcommand(name: str, **options: Any) -> Callable[[Callable[..., None]], Declare]:
    """Makes a function that adds a subcommand's arguments the one that declares it.

    Args:
        name: What the user types (``'record'``).
        **options: The subcommand parser's ``help``, ``description``, ``formatter_class``.

    Returns:
        A decorator: the decorated ``add_X(parser)`` becomes ``add_X(subparsers)``, which
        adds the parser named ``name`` to the top-level subcommands, declares its arguments
        and returns it.
    """

    def declare(add_arguments: Callable[[argparse.ArgumentParser], None]) -> Declare:
        @functools.wraps(add_arguments)
        def add(subparsers: Subparsers) -> argparse.ArgumentParser:
            parser = subparsers.add_parser(name, **options)
            add_arguments(parser)
            return parser

        return add

    return declare


POSE_TOPIC = TIP_POSE
REFERENCE_TOPIC = TRACKER_POINT
CAMERA_INFO_TOPIC = CAMERA_INFO

#: The simulated laser tracker's defaults (``synthetic.tracker.ReferenceSensorOptions``).
TRACKER_RATE_HZ = 1000.0
TRACKER_NOISE_M = 15e-6
TRACKER_CLOCK_OFFSET_S = 7.3e-3
TRACKER_POSE = (1.2, -3.0, 0.35, 4.0, -8.0, 100.0)


TRACK_DESCRIPTION = """\
Tracks the tip in camera footage and writes OUT, a rosbag2 bag (MCAP) with /tip_pose.

SRC is one of:
  a rosbag2 folder     sensor_msgs/Image (mono8, mono16, bgr8, rgb8, bayer_rggb8, bayer_bggr8,
                       bayer_gbrg8, bayer_grbg8) or sensor_msgs/CompressedImage (jpeg, png)
                       on --image-topic (default /camera/image_raw, else
                       /camera/image_raw/compressed); stamps from the messages, intrinsics
                       from --camera-info-topic. OUT is a copy of it plus /tip_pose (a
                       /tip_pose already there is replaced), without its images unless
                       --keep-images.
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

BEAM_CONFIG_HELP = 'beam parameter file (default: config/paper_beam.yaml)'


@_subcommand('reproduce', help="the paper's Tables B.1, B.2, frequencies and static deflections")
def add_reproduce(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam reproduce``."""
    parser.add_argument('--config', help=BEAM_CONFIG_HELP)
    parser.add_argument('--json', metavar='FILE', help='write the results as JSON')


@_subcommand('synth', help='write a synthetic drop-test bag')
def add_synth(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam synth``."""
    parser.add_argument('out', help='bag folder to create (must not exist, unless --force)')
    parser.add_argument(
        '--force', action='store_true', help='replace OUT when it is a bag (or a folder of bags)'
    )
    parser.add_argument(
        '--loads',
        metavar='KG,KG,...',
        help='write a campaign: OUT becomes a folder of bags, one per load and seed',
    )
    parser.add_argument(
        '--seeds', type=int, default=1, metavar='N', help='with --loads: bags per load (1)'
    )
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
        help='hide a physical effect of the diagnosis in the data (repeatable); '
        '--effect none hides nothing',
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
    arm = parser.add_argument_group('a flexible arm moved along a trajectory (doc/arm.md)')
    arm.add_argument(
        '--arm',
        metavar='FILE',
        help='arm configuration file: write /joint_states, /tip_pose, /tip_pose_truth and '
        '/beam_markers of the arm following --trajectory (--duration: the whole record, at '
        "least the trajectory's; --images: a tip camera, its board in view after the move)",
    )
    arm.add_argument('--trajectory', metavar='FILE', help='joint trajectory file (CSV) with --arm')


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


@_subcommand(
    'track',
    help='track the tip in a bag, a video or an image folder, offline',
    description=TRACK_DESCRIPTION,
    formatter_class=argparse.RawDescriptionHelpFormatter,
)
def add_track(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam track``."""
    parser.add_argument('src', help='rosbag2 folder, video file, or folder of images')
    parser.add_argument('out', help='bag folder to create (must not exist, unless --force)')
    parser.add_argument(
        '--force', action='store_true', help='replace OUT when it is a bag (or a folder of bags)'
    )
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
        '--camera-info-topic', default=CAMERA_INFO_TOPIC, help=f'({CAMERA_INFO_TOPIC})'
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
    parser.add_argument(
        '--keep-images',
        action='store_true',
        help="a bag's image topics are copied into OUT too (by default they are left out)",
    )


@_subcommand('analyze', help='identify frequency, damping and stiffness')
def add_analyze(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam analyze``."""
    parser.add_argument(
        'bag',
        nargs='+',
        metavar='BAG',
        help='rosbag2 folder with /tip_pose (and /tip_load) or /tip_imu; several with --fit-links',
    )
    parser.add_argument('--json', help='write the result as JSON to this file')
    parser.add_argument('--plots', help='write figures (PNG) into this folder')
    parser.add_argument('--config', help='beam parameter file (default: config/paper_beam.yaml)')
    parser.add_argument(
        '--identifier-config', help='identifier parameter file (default: config/identifier.yaml)'
    )
    parser.add_argument(
        '--max-modes',
        metavar='N',
        help='report at most N modes, each only when it stands out of the noise '
        "(default: the identifier config's fit.max_modes, 3)",
    )
    parser.add_argument(
        '--band',
        metavar='LOW,HIGH',
        help='look for modes between LOW and HIGH Hz only (default: up to the Nyquist '
        "frequency of a record, the identifier config's band for a drop test)",
    )
    add_report(parser)
    arm = parser.add_argument_group("an arm's bags (doc/arm.md)")
    arm.add_argument(
        '--arm',
        metavar='FILE',
        help="the arm's configuration file: the free vibration after the last move on "
        "/joint_states, beside the arm's modes at the final joint angles; with --fit-links, "
        'the nominal link values',
    )
    arm.add_argument(
        '--fit-links',
        action='store_true',
        help="fit each link's k_total_nm_per_rad and damping_beta to the modes measured after "
        'the last move of each BAG (moves ending in different configurations, each with a '
        'short quick step of the outer joint so that every mode rings); with --arm',
    )
    arm.add_argument(
        '--fit-payload',
        action='store_true',
        help='fit the payload mass (kg) to the modes measured after the last move of each BAG, '
        'the links as --arm gives them (the arm that picked up an unknown part); with --arm',
    )
    arm.add_argument(
        '--write-arm',
        metavar='OUT',
        help='with --fit-links or --fit-payload: also write the arm file with the fitted values '
        '(everything else as --arm)',
    )


@_subcommand(
    'shape',
    help='shape a joint trajectory so that it leaves no vibration (ZV, ZVD, EI)',
    description='Convolves a joint trajectory file (time_s,joint_1,...,joint_n) with an '
    'input shaper that cancels the given modes, and writes the shaped trajectory sampled at '
    '1 kHz (or at the input rate if finer). The modes come from --frequency-hz and '
    '--damping-ratio (repeat both for several modes) or from --params, the JSON of '
    'lumpbeam analyze.',
)
def add_shape(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam shape IN OUT``."""
    parser.add_argument('input', metavar='IN', help='joint trajectory file (CSV)')
    parser.add_argument('output', metavar='OUT', help='shaped trajectory file to write (CSV)')
    parser.add_argument(
        '--shaper',
        choices=SHAPER_NAMES,
        default='zvd',
        help='zv: shortest, exact frequency only; zvd: robust to some 15 %% frequency error; '
        'ei: extra-insensitive, at most 5 %% vibration over a wider band (default: zvd)',
    )
    parser.add_argument(
        '--frequency-hz',
        type=float,
        action='append',
        metavar='F',
        help="a mode's natural frequency, Hz (repeat for several modes)",
    )
    parser.add_argument(
        '--damping-ratio',
        type=float,
        action='append',
        metavar='Z',
        help="that mode's damping ratio, in [0, 1) (repeat as --frequency-hz, or give it once "
        'for every mode; default 0)',
    )
    parser.add_argument(
        '--params',
        metavar='FILE',
        help='take the modes from this JSON of lumpbeam analyze (its modes list, else its '
        'natural_frequency_hz and damping_ratio)',
    )
    parser.add_argument(
        '--json', metavar='FILE', help='write the impulses and the time added as JSON'
    )
    model = parser.add_argument_group("shaping by an arm's model (doc/arm.md)")
    model.add_argument(
        '--arm',
        metavar='FILE',
        help="shape each move (a stretch between rests) for the first modes of this arm's "
        'model at its final angles, in place of --frequency-hz or --params',
    )
    model.add_argument(
        '--payload-kg',
        type=non_negative_float,
        metavar='M',
        help="with --arm: the payload at the last link's free end, kg (default: the file's)",
    )
    model.add_argument(
        '--max-modes',
        type=positive_int,
        metavar='N',
        help=f'with --arm: modes shaped per move, slowest first (default {DEFAULT_MAX_MODES})',
    )
    model.add_argument(
        '--tune',
        action='store_true',
        help="with --arm: tune each move's impulses on the model's simulation of that move "
        '(fast moves through large angles, which no fixed shaper cancels)',
    )


@_subcommand(
    'modes',
    help="an arm's modes at given joint angles",
    description="The arm's linear modes about its static equilibrium at the joint angles "
    '--q: natural frequency and damping ratio of every underdamped mode, slowest first.',
)
def add_modes(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam modes``."""
    parser.add_argument('--arm', metavar='FILE', required=True, help='arm configuration file')
    parser.add_argument(
        '--q',
        metavar='Q1,...,QN',
        required=True,
        help='joint angles, rad, one per joint (write --q=-0.5,1 for a negative first angle)',
    )
    parser.add_argument(
        '--payload-kg',
        type=non_negative_float,
        metavar='M',
        help="payload at the last link's free end, kg (default: the file's)",
    )
    parser.add_argument('--json', metavar='FILE', help='write the modes as JSON')


@_subcommand(
    'diagnose',
    help='find the effect the model misses, add it, show the gap shrink',
    description='Fits the nominal beam and each effect of the library to a drop-test '
    'bag (/tip_pose, /tip_load), names the missing effect (or none, or unexplained) and '
    'reports the gap between model and measurement before and after adding it.',
)
def add_diagnose(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam diagnose``."""
    parser.add_argument('bag', help='bag folder with /tip_pose and /tip_load')
    parser.add_argument('--config', help='nominal beam file (default: config/paper_beam.yaml)')
    parser.add_argument('--json', metavar='FILE', help='write the result as JSON')
    parser.add_argument('--plots', metavar='DIR', help='write figures (PNG) to this folder')
    parser.add_argument(
        '--write-model', metavar='FILE', help='write the augmented beam parameter file'
    )
    add_report(parser)


@_subcommand(
    'compare',
    help='camera poses against a reference sensor (/tracker/point)',
    description='Aligns a reference sensor (a laser tracker on the tip) to the camera in '
    'time and space from the data alone, then reports their difference, the clock '
    'offset (tracker_stamp = camera_stamp + offset) and the frequency and damping '
    'identified from each.',
)
def add_compare(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam compare``."""
    parser.add_argument('bag', help='bag folder with /tip_pose and /tracker/point')
    parser.add_argument('--json', metavar='FILE', help='write the result as JSON')
    parser.add_argument('--plots', metavar='DIR', help='write compare.png (Fig. B.8) here')
    parser.add_argument('--config', help='beam parameter file (default: config/paper_beam.yaml)')
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
    add_report(parser)


def html_file(text: str) -> str:
    """Argument type: a file name ending in ``.html`` or ``.htm``.

    Checked when the arguments are parsed, so a wrong name is refused before a long analysis
    runs (the report writer refuses it too).

    Args:
        text: The option's value.

    Returns:
        The file name.

    Raises:
        argparse.ArgumentTypeError: Another suffix.
    """
    if Path(text).suffix.lower() not in ('.html', '.htm'):
        raise argparse.ArgumentTypeError(f'the report is an HTML file (FILE.html), not {text!r}')
    return text


def add_report(parser: argparse.ArgumentParser) -> None:
    """Declares ``--report FILE.html``.

    Args:
        parser: The subcommand's parser.
    """
    parser.add_argument(
        '--report', type=html_file, metavar='FILE.html', help='write a self-contained HTML report'
    )


def add_namespace(parser: argparse.ArgumentParser, what: str) -> None:
    """Declares ``--namespace NS`` (checked by rclpy when the command runs).

    Args:
        parser: A subcommand's parser.
        what: What the namespace does for that command.
    """
    parser.add_argument('--namespace', metavar='NS', help=f'{what}, e.g. /beam_a')


@_subcommand(
    'record',
    help='record topics from the live graph into a bag',
    description='Records topics into a new rosbag2 bag (MCAP, CDR). Stops on Ctrl-C, '
    'SIGTERM or after --duration; a killed recorder loses at most the last flush period.',
)
def add_record(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam record OUT [TOPIC...] [--all]``."""
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
    add_namespace(parser, "record this namespace's topics, stored under the bag's names")


@_subcommand(
    'repair',
    help='copy the readable messages of a damaged bag into a whole one',
    description='Copies every readable message of a bag whose recorder was killed (or '
    'whose data file is damaged) into a new bag with a complete MCAP summary and exact '
    'counts in metadata.yaml, so that rosbags, ros2 bag and the mcap tools open it '
    '(as `mcap recover` does for a bare MCAP file). The damaged bag is left as it is.',
)
def add_repair(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam repair BAG [OUT]``."""
    parser.add_argument('bag', help='the damaged rosbag2 folder (MCAP)')
    parser.add_argument('out', nargs='?', help='bag folder to create (default: BAG-repaired)')


IMPORT_DESCRIPTION = """\
Writes OUT, a rosbag2 bag (MCAP), from a measured record: a displacement becomes /tip_pose
(the value along --axis of beam_base, identity orientation), an acceleration /tip_imu
(sensor_msgs/Imu, linear_acceleration along --axis of the frame tip).

SRC is one of:
  a CSV file (.csv, .tsv, .txt)  one header row of names; fields separated by , or ; or tab
                                 (with ; or tab, a decimal comma is read too), or spaces
                                 under a '# name name' line (numpy.savetxt); --column NAME
                                 (needed when there are several), --time-column NAME or --rate
  a LabVIEW file (.lvm)          the channel by its name in the last header (--column, needed
                                 when there are several); time from its X_Value column where
                                 it has one, else from X0 and Delta_X; . or , decimals as its
                                 header says
  a NumPy file (.npy, .npz)      a 1-D array, a 2-D one with --column INDEX (and
                                 --time-column INDEX), or an .npz array by --column NAME
  a MATLAB file (.mat, v7)       a variable by --column NAME, --time-column NAME or --rate
Stamps are --start plus the record's time. An empty cell is a gap: its sample is left out and
counted. Time must increase.
"""


@_subcommand(
    'import',
    help='write a bag from a lab file (CSV, LabVIEW .lvm, NumPy, MATLAB)',
    description=IMPORT_DESCRIPTION,
    formatter_class=argparse.RawDescriptionHelpFormatter,
)
def add_import(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam import SRC OUT``."""
    parser.add_argument('src', help='the measured record')
    parser.add_argument('out', help='bag folder to create (must not exist)')
    parser.add_argument(
        '--quantity', required=True, choices=tuple(UNITS), help='what the record measured'
    )
    parser.add_argument('--column', help='the channel: a name, or an index of a 2-D .npy')
    when = parser.add_mutually_exclusive_group()
    when.add_argument('--time-column', help='the time column or array, s')
    when.add_argument('--rate', type=positive_float, help='the sampling rate, Hz')
    units = '; '.join(
        f'{quantity}: {", ".join(names)} (default {next(iter(names))})'
        for quantity, names in UNITS.items()
    )
    parser.add_argument('--unit', help=f"the record's unit ({units})")
    parser.add_argument(
        '--axis', choices=AXES, default=AXES[-1], help=f'measured along (default {AXES[-1]})'
    )
    parser.add_argument(
        '--start', default=DEFAULT_START, help=f'ISO 8601 time of t = 0 (default {DEFAULT_START})'
    )


@_subcommand(
    'doctor',
    help="check bags as the mcap CLI's doctor does",
    description="Checks each bag's MCAP files (record framing, chunk CRCs and time "
    'ranges, log-time order, message and chunk indexes, statistics) and that '
    'metadata.yaml counts what the files hold, as `mcap doctor` does. Prints each '
    'problem on its own line, or that the bag is clean; exit code 1 when any bag has '
    'a problem.',
)
def add_doctor(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam doctor BAG [BAG ...]``."""
    parser.add_argument('bags', nargs='+', metavar='BAG', help='rosbag2 folders (MCAP)')


@_subcommand(
    'launch',
    help='start the nodes of a ROS 2 YAML launch file (launch/*.launch.yaml)',
    description='Starts the nodes of a ROS 2 YAML launch file, as `ros2 launch` does, where '
    "ROS's own launch is not installed (ROS from pip): each node a child process, all "
    'stopped together on Ctrl-C or SIGTERM, or when one of them fails. The shipped files '
    "are in the share folder's launch/ (the repository's launch/).",
)
def add_launch(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam launch FILE [NAME:=VALUE ...]``."""
    parser.add_argument('file', help='the .launch.yaml file')
    parser.add_argument(
        'arguments', nargs='*', metavar='NAME:=VALUE', help="the file's launch arguments"
    )


@_subcommand(
    'play',
    help='replay a bag into the live graph with /clock',
    description='Publishes a bag with its original relative timing and /clock '
    '(for nodes run with use_sim_time). Stops at the end, on Ctrl-C or on SIGTERM.',
)
def add_play(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam play BAG``."""
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
    add_namespace(parser, "publish the bag's topics in this namespace (/clock stays global)")


@_subcommand('bench', help='speed benchmarks against same-run baselines')
def add_bench(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam bench``."""
    parser.add_argument(
        '--only', action='append', metavar='SUITE', help='run only this suite (repeatable)'
    )
    parser.add_argument('--quick', action='store_true', help='small inputs (a smoke test)')
    parser.add_argument('--json', metavar='FILE', help='write the results as JSON')


@_subcommand(
    'demo',
    help='the whole pipeline on the built-in synthetic experiment',
    description='Synthesizes a drop test, replays it through the live node graph '
    '(player, simulator, identifier, recorder as separate processes on a private ROS '
    'domain), analyzes the recording and draws measured against predicted.',
)
def add_demo(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam demo``."""
    parser.add_argument(
        '--out',
        type=Path,
        help='output folder (default results, with --arm results/arm, with --workspace '
        'results/workspace)',
    )
    parser.add_argument(
        '--duration', type=positive_float, default=12.0, help='record length, s (default 12)'
    )
    parser.add_argument('--seed', type=int, default=0, help='seed of the pose noise')
    parser.add_argument(
        '--adopt', action='store_true', help='the simulator adopts the live identified values'
    )
    parser.add_argument('--domain-id', type=int, help='ROS domain (default: a free one)')
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
    parser.add_argument(
        '--arm',
        nargs='?',
        const='',
        metavar='FILE',
        help='the input-shaping loop on a simulated flexible arm instead of the drop test: an '
        'unshaped move rings, its modes are identified live, the move back is shaped '
        '(arm file; default config/arm_rotary.yaml, with --workspace config/arm_2link.yaml)',
    )
    parser.add_argument(
        '--workspace',
        action='store_true',
        help='with or without --arm: a two-link arm whose links are 20%% off its file visits '
        'five configurations; the identifier learns the links from the first ring-downs, '
        'the later moves are shaped by the learned model',
    )


@_subcommand(
    'campaign',
    help='analyze (and diagnose) many bags on a Dask cluster',
    description='Runs lumpbeam analyze (and with --diagnose, lumpbeam diagnose) over '
    'many bags on Dask, one row per bag in RESULTS/results.parquet and .csv, then fits '
    "the beam's EI and mass across the campaign (RESULTS/report.html). A rerun skips "
    'the bags already done.',
)
def add_campaign(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam campaign``."""
    parser.add_argument('bags', nargs='+', metavar='BAG', help='bag folders or glob patterns')
    parser.add_argument('--out', required=True, metavar='RESULTS', help='results folder')
    parser.add_argument('--diagnose', action='store_true', help='also run lumpbeam diagnose')
    parser.add_argument(
        '--scheduler', metavar='ADDRESS', help='a running Dask scheduler (tcp://host:8786)'
    )
    parser.add_argument(
        '--connect-timeout',
        type=positive_float,
        default=10.0,
        metavar='S',
        help='seconds to wait for --scheduler to answer (10)',
    )
    parser.add_argument(
        '--workers', type=positive_int, default=2, metavar='N', help='local cluster workers (2)'
    )
    parser.add_argument('--config', help='beam parameter file (default: config/paper_beam.yaml)')
    parser.add_argument('--identifier-config', help='identifier parameter file')


def port_number(text: str) -> int:
    """Argument type of ``--port``: 0 (any free port) to 65535."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'{text!r} is not a port number') from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f'port must be in 0..65535, got {value}')
    return value


@_subcommand(
    'view',
    help='serve the live graph (or a bag) to Foxglove over its WebSocket protocol',
    description='Serves the live ROS graph, or a bag replayed in its own timing, to '
    'Foxglove at ws://HOST:PORT (messages as their CDR bytes, ros2msg schemas).',
)
def add_view(parser: argparse.ArgumentParser) -> None:
    """Declares ``lumpbeam view``."""
    parser.add_argument('--bag', help='replay this bag instead of the live graph')
    parser.add_argument(
        '--port', type=port_number, default=8765, help='TCP port (0: any free one)'
    )
    parser.add_argument('--host', default='127.0.0.1', help='address to listen on')
    parser.add_argument('--topics', nargs='+', metavar='TOPIC', help='only these topics')
    parser.add_argument('--rate', type=positive_float, default=1.0, help='bag speed factor')
    parser.add_argument('--loop', action='store_true', help='replay the bag again at its end')
    parser.add_argument('--duration', type=positive_float, help='stop after this many seconds')
    parser.add_argument(
        '--arm',
        metavar='FILE',
        help="with --bag: draw a recorded arm's bag on /beam_markers, the arm of FILE moved "
        "along its /joint_states (in place of the bag's own markers)",
    )
