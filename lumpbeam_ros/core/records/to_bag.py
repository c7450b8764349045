"""A measured record written as a bag: displacement on ``/tip_pose``, acceleration on ``/tip_imu``.

The bag is what the camera or an IMU driver would have recorded: a displacement becomes the
tip's position along one axis of ``beam_base`` (identity orientation), an acceleration the
``linear_acceleration`` along one axis of the frame ``tip``. Values are converted to SI units
(:data:`~.units.UNITS`); samples without a value are left out and counted. Each message is stamped
and logged at ``start`` plus its time in the record.
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from lumpbeam_ros.base.errors import RecordError
from lumpbeam_ros.base.interface import (
    BASE_FRAME,
    IMU_TYPE,
    POSE_STAMPED,
    TIP_FRAME,
    TIP_IMU,
    TIP_POSE,
)
from lumpbeam_ros.core.bagio import convert
from lumpbeam_ros.core.bagio.writer import BagWriter
from lumpbeam_ros.core.records.labfile import LabRecord
from lumpbeam_ros.core.records.units import AXES, DEFAULT_START, UNITS

#: Where each quantity goes: its topic and its frame.
TOPICS = {'displacement': (TIP_POSE, BASE_FRAME), 'acceleration': (TIP_IMU, TIP_FRAME)}


@dataclass(frozen=True)
class ImportOptions:
    """How a record becomes a bag.

    Attributes:
        quantity: ``displacement`` or ``acceleration``.
        unit: The record's unit (:data:`~.units.UNITS`); ``None`` for the quantity's default.
        axis: The axis it is measured along.
        start: The stamp of time 0, ISO 8601 (a time zone, else UTC).
    """

    quantity: str
    unit: str | None = None
    axis: str = 'z'
    start: str = DEFAULT_START

    def factor(self) -> float:
        """The factor from the record's unit to SI.

        Raises:
            RecordError: An unknown quantity or unit, or an unknown axis.
        """
        units = UNITS.get(self.quantity)
        if units is None:
            raise RecordError(f'unknown quantity {self.quantity!r}; one of {", ".join(UNITS)}')
        if self.axis not in AXES:
            raise RecordError(f'unknown axis {self.axis!r}; one of {", ".join(AXES)}')
        unit = next(iter(units)) if self.unit is None else self.unit
        if unit not in units:
            raise RecordError(f'unit {unit!r} is not one of a {self.quantity}: {", ".join(units)}')
        return units[unit]

    def start_s(self) -> float:
        """The start as seconds since the Unix epoch.

        Raises:
            RecordError: Not an ISO 8601 time, or before the epoch.
        """
        text = self.start.strip()
        try:
            when = datetime.fromisoformat(text[:-1] + '+00:00' if text.endswith('Z') else text)
        except ValueError:
            raise RecordError(
                f'start {self.start!r} is not an ISO 8601 time (e.g. {DEFAULT_START})'
            ) from None
        if when.tzinfo is None:
            when = when.replace(tzinfo=timezone.utc)
        seconds = when.timestamp()
        if seconds < 0.0:
            raise RecordError(f'start {self.start!r} is before 1970: a ROS stamp cannot hold it')
        return seconds


@dataclass(frozen=True)
class ImportSummary:
    """What :func:`write_record_bag` wrote.

    Attributes:
        topic: The topic.
        messages: Messages written.
        gaps: Samples left out for want of a value.
        start_s: The first stamp, s since the epoch.
        duration_s: From the first to the last sample, s.
        rate_hz: The record's median rate, Hz.
    """

    topic: str
    messages: int
    gaps: int
    start_s: float
    duration_s: float
    rate_hz: float


def write_record_bag(record: LabRecord, out: str | Path, options: ImportOptions) -> ImportSummary:
    """Writes a record as a new bag.

    Args:
        record: The record.
        out: The bag folder to create.
        options: Its quantity, unit, axis and start.

    Returns:
        What was written.

    Raises:
        RecordError: Bad options, or a record whose stamps would not fit a ROS time.
        BagError: The bag cannot be written.
    """
    factor = options.factor()
    start_ns = round(options.start_s() * 1e9)
    topic, frame = TOPICS[options.quantity]
    # Whole nanoseconds from the record's own time: a float of seconds since 1970 would
    # round each stamp by tens of nanoseconds.
    offsets_ns = np.round(record.t * 1e9)
    if start_ns + offsets_ns[0] < 0 or start_ns + offsets_ns[-1] >= 2**31 * 10**9:
        raise RecordError(
            f'{record.source}: its time ({record.t[0]:g}..{record.t[-1]:g} s) from the start '
            f'{options.start} does not fit a ROS stamp'
        )
    keep = np.isfinite(record.values)
    values = record.values * factor
    axis = AXES.index(options.axis)
    vector = [0.0, 0.0, 0.0]
    with BagWriter(out) as bag:
        bag.add_topic(topic, IMU_TYPE if topic == TIP_IMU else POSE_STAMPED)
        for offset_ns, value in zip(offsets_ns[keep], values[keep], strict=True):
            vector[axis] = float(value)
            ns = start_ns + int(offset_ns)
            if topic == TIP_IMU:
                message = convert.imu_acceleration(ns, (vector[0], vector[1], vector[2]), frame)
            else:
                message = convert.pose_stamped_6dof(
                    ns, (vector[0], vector[1], vector[2]), (0.0, 0.0, 0.0, 1.0), frame
                )
            bag.write_message(topic, message, ns)
    return ImportSummary(
        topic=topic,
        messages=int(np.count_nonzero(keep)),
        gaps=record.gaps,
        start_s=(start_ns + float(offsets_ns[0])) * 1e-9,
        duration_s=float(record.t[-1] - record.t[0]),
        rate_hz=record.rate_hz,
    )
