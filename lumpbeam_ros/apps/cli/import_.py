"""``lumpbeam import SRC OUT``: a bag from a lab's measured record (doc/interfaces.md)."""

from __future__ import annotations

import argparse
import sys
from datetime import datetime, timezone

from lumpbeam_ros.core.records.labfile import ChannelChoice, read_lab_file
from lumpbeam_ros.core.records.to_bag import ImportOptions, write_record_bag


def run(args: argparse.Namespace) -> int:
    """Reads the record, writes the bag, says what it holds."""
    options = ImportOptions(
        quantity=args.quantity, unit=args.unit, axis=args.axis, start=args.start
    )
    options.factor()  # a bad unit is refused before the file is read
    options.start_s()
    choice = ChannelChoice(column=args.column, time_column=args.time_column, rate_hz=args.rate)
    record = read_lab_file(args.src, choice)
    summary = write_record_bag(record, args.out, options)
    if summary.gaps:
        print(
            f'lumpbeam import: warning: {args.src}: {summary.gaps} sample(s) of '
            f'{record.name!r} without a value left out',
            file=sys.stderr,
        )
    start = datetime.fromtimestamp(summary.start_s, tz=timezone.utc).isoformat()
    print(
        f'wrote {args.out}: {summary.messages} messages on {summary.topic} from {record.name!r} '
        f'of {args.src}, {summary.duration_s:.6g} s at {summary.rate_hz:.6g} Hz from {start}'
    )
    return 0
