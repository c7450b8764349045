"""Entry point of the ``lumpbeam`` command (doc/interfaces.md, "The lumpbeam command").

Each subcommand is registered here by name with the function that declares its arguments
(:mod:`lumpbeam_ros.apps.cli.arguments`, standard library only) and the ``'module:function'``
that runs it, imported only once the command is chosen: ``lumpbeam --help`` and
``lumpbeam COMMAND --help`` load no numpy, OpenCV or ROS. This module only dispatches: a
:class:`~lumpbeam_ros.base.errors.LumpbeamError`, a missing optional package or a path the
system refuses (an ``OSError`` naming a file: a name too long, no permission, no space)
becomes one line on stderr and exit code 2. SIGTERM stops a command as Ctrl-C does (files
being written are closed or removed on the way out), exit code 128 + the signal, also under
``python -m lumpbeam_ros.apps.cli.main`` (:mod:`lumpbeam_ros.base.interrupts` says why that needs
care).
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import NamedTuple

from lumpbeam_ros import __version__
from lumpbeam_ros.apps.cli import arguments
from lumpbeam_ros.apps.cli.dependencies import missing_package_message
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interrupts import interrupt_on_signals, restore_handlers, signal_number

USAGE_ERROR = 2


class Command(NamedTuple):
    """A subcommand (a named tuple: dataclasses would double the start-up's imports).

    Attributes:
        name: What the user types.
        declare: Adds the subcommand's parser to the top-level subparsers.
        target: ``'module:function'`` of the function that runs it: parsed arguments in,
            exit code out.
    """

    name: str
    declare: arguments.Declare
    target: str


#: The subcommands, in the order ``lumpbeam --help`` lists them.
COMMANDS = (
    Command('reproduce', arguments.add_reproduce, 'lumpbeam_ros.apps.cli.reproduce:run'),
    Command('synth', arguments.add_synth, 'lumpbeam_ros.apps.cli.synth:run'),
    Command('track', arguments.add_track, 'lumpbeam_ros.apps.cli.track:run'),
    Command('import', arguments.add_import, 'lumpbeam_ros.apps.cli.import_:run'),
    Command('analyze', arguments.add_analyze, 'lumpbeam_ros.apps.cli.analyze:run'),
    Command('shape', arguments.add_shape, 'lumpbeam_ros.apps.cli.shape:run'),
    Command('modes', arguments.add_modes, 'lumpbeam_ros.apps.cli.modes:run'),
    Command('diagnose', arguments.add_diagnose, 'lumpbeam_ros.apps.cli.diagnose:run'),
    Command('compare', arguments.add_compare, 'lumpbeam_ros.apps.cli.compare:run'),
    Command('record', arguments.add_record, 'lumpbeam_ros.apps.cli.record:run'),
    Command('repair', arguments.add_repair, 'lumpbeam_ros.apps.cli.repair:run'),
    Command('doctor', arguments.add_doctor, 'lumpbeam_ros.apps.cli.doctor:run'),
    Command('play', arguments.add_play, 'lumpbeam_ros.apps.cli.play:run'),
    Command('launch', arguments.add_launch, 'lumpbeam_ros.apps.cli.launch:run'),
    Command('bench', arguments.add_bench, 'lumpbeam_ros.apps.cli.bench:run'),
    Command('demo', arguments.add_demo, 'lumpbeam_ros.apps.cli.demo:run'),
    Command('campaign', arguments.add_campaign, 'lumpbeam_ros.apps.cli.campaign:run'),
    Command('view', arguments.add_view, 'lumpbeam_ros.apps.cli.view:run'),
)


def build_parser() -> argparse.ArgumentParser:
    """Builds the parser with every subcommand, importing none of them.

    Returns:
        The top-level parser; a parse sets ``target`` to the chosen command's function.
    """
    parser = argparse.ArgumentParser(
        prog='lumpbeam',
        description='Lumped-parameter flexible beams: reproduce, track, identify, diagnose.',
    )
    parser.add_argument('--version', action='version', version=f'%(prog)s {__version__}')
    subparsers = parser.add_subparsers(
        dest='command',
        metavar='COMMAND',
        required=True,
        parser_class=arguments.IntermixedParser,
    )
    for command in COMMANDS:
        command.declare(subparsers).set_defaults(target=command.target)
    return parser


def load_target(target: str) -> Callable[[argparse.Namespace], int | None]:
    """Imports the function that runs a subcommand.

    Args:
        target: ``'module:function'``.

    Returns:
        The function.

    Raises:
        ModuleNotFoundError: The module or one of its dependencies is not installed.
    """
    module, _, function = target.partition(':')
    return getattr(importlib.import_module(module), function)


def main(argv: Sequence[str] | None = None) -> int:
    """Runs ``lumpbeam``.

    Args:
        argv: Arguments without the program name; ``sys.argv[1:]`` when ``None``.

    Returns:
        The exit code: 0 on success, 2 for a user's mistake or a missing optional package,
        else the subcommand's code.
    """
    args = build_parser().parse_args(argv)
    with _signals_interrupt():
        try:
            return int(load_target(args.target)(args) or 0)
        except LumpbeamError as exc:
            print(f'lumpbeam {args.command}: error: {exc}', file=sys.stderr)
            return USAGE_ERROR
        except ModuleNotFoundError as exc:
            message = missing_package_message(args.command, exc)
            if message is None:
                raise
            print(message, file=sys.stderr)
            return USAGE_ERROR
        except OSError as exc:
            if exc.filename is None:
                raise
            print(f'lumpbeam {args.command}: error: {_os_error_line(exc)}', file=sys.stderr)
            return USAGE_ERROR
        except KeyboardInterrupt as exc:
            print(f'lumpbeam {args.command}: interrupted', file=sys.stderr)
            return 128 + signal_number(exc)


def _os_error_line(exc: OSError) -> str:
    """``OSError`` as one line: the path(s) and what the system said."""
    paths = ' -> '.join(str(p) for p in (exc.filename, exc.filename2) if p is not None)
    return f'{paths}: {exc.strerror or exc}'


@contextmanager
def _signals_interrupt() -> Iterator[None]:
    """Within the block, SIGINT and SIGTERM raise an interrupt (``KeyboardInterrupt``).

    Python's default SIGTERM ends the process at once, leaving a bag being written without
    its summary. A command that handles its signals itself (``play``, ``record``) installs
    its own handlers inside the block. Outside the main thread nothing is changed.
    """
    previous = interrupt_on_signals()
    try:
        yield
    finally:
        restore_handlers(previous)


if __name__ == '__main__':
    sys.exit(main())
