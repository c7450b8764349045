"""Entry point of the ``lumpbeam`` command (SPEC section 5).

Each subcommand lives in its own module under :mod:`lumpbeam_ros.cli` with a
``register(subparsers)`` function that adds its parser and sets ``handler``: a function of
the parsed arguments returning the exit code. This module only dispatches and turns a
:class:`~lumpbeam_ros.errors.LumpbeamError` into one line on stderr and exit code 2.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from lumpbeam_ros import __version__
from lumpbeam_ros.errors import LumpbeamError

#: Subcommand modules, in the order ``lumpbeam --help`` lists them.
COMMANDS = (
    'reproduce',
    'synth',
    'track',
    'analyze',
    'diagnose',
    'compare',
    'record',
    'play',
    'bench',
    'view',
    'demo',
    'campaign',
)

USAGE_ERROR = 2


def build_parser() -> argparse.ArgumentParser:
    """Builds the parser with every available subcommand.

    Returns:
        The top-level parser.
    """
    parser = argparse.ArgumentParser(
        prog='lumpbeam',
        description='Lumped-parameter flexible beams: reproduce, track, identify, diagnose.',
    )
    parser.add_argument('--version', action='version', version=f'%(prog)s {__version__}')
    subparsers = parser.add_subparsers(dest='command', metavar='COMMAND', required=True)
    for name in COMMANDS:
        try:
            module = importlib.import_module(f'lumpbeam_ros.cli.{name}')
        except ModuleNotFoundError as exc:
            if exc.name != f'lumpbeam_ros.cli.{name}':
                raise
            continue  # not built yet
        module.register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Runs ``lumpbeam``.

    Args:
        argv: Arguments without the program name; ``sys.argv[1:]`` when ``None``.

    Returns:
        The exit code: 0 on success, 2 for a user's mistake, else the subcommand's code.
    """
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.handler(args) or 0)
    except LumpbeamError as exc:
        print(f'lumpbeam {args.command}: error: {exc}', file=sys.stderr)
        return USAGE_ERROR
    except KeyboardInterrupt:
        print(f'lumpbeam {args.command}: interrupted', file=sys.stderr)
        return 130


if __name__ == '__main__':
    sys.exit(main())
