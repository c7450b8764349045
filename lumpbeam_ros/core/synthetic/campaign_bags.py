"""A synthetic test campaign: one drop-test bag per hanging load and noise seed."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag


def parse_loads(text: str) -> list[float]:
    """Parses ``--loads 0.5,1,2,5,10``.

    Args:
        text: Comma-separated masses, kg.

    Returns:
        The loads, in the order given.

    Raises:
        LumpbeamError: Empty, not numbers, or a load that is not positive and finite.
    """
    loads = []
    for part in text.split(','):
        try:
            value = float(part)
        except ValueError:
            raise LumpbeamError(f'--loads {text!r}: {part.strip()!r} is not a number') from None
        if not math.isfinite(value) or value <= 0.0:
            raise LumpbeamError(f'--loads {text!r}: every load must be positive, got {part!r}')
        loads.append(value)
    return loads


def bag_name(load_kg: float, seed: int) -> str:
    """The folder name of one bag of the campaign, e.g. ``load_0.5kg_seed2``."""
    return f'load_{load_kg:g}kg_seed{seed}'


def write_campaign(
    out: str | Path,
    beam: BeamParameters,
    drop: DropTestConfig,
    options: SynthOptions,
    loads: Sequence[float],
    seeds: int,
) -> list[Path]:
    """Writes ``len(loads) * seeds`` drop-test bags into a new folder.

    Each bag is :func:`~lumpbeam_ros.core.synthetic.drop_test.write_drop_test_bag` with the
    drop test's load replaced and the noise seed ``options.seed + i`` for ``i < seeds``.

    Args:
        out: The folder to create (it must not exist).
        beam: The nominal beam.
        drop: The drop test (its load is replaced per bag).
        options: Duration, rate, noise, hidden effects; the seed is the first one.
        loads: Hanging loads, kg.
        seeds: Bags per load.

    Returns:
        The bag folders written.

    Raises:
        LumpbeamError: ``out`` exists, ``seeds`` < 1, or a bag cannot be written.
    """
    out = Path(out)
    if out.exists():
        raise LumpbeamError(f'{out}: exists; a campaign is written into a new folder')
    if seeds < 1:
        raise LumpbeamError(f'--seeds must be 1 or more, got {seeds}')
    out.mkdir(parents=True)
    bags = []
    for load in loads:
        for i in range(seeds):
            bag = out / bag_name(load, options.seed + i)
            write_drop_test_bag(
                bag,
                beam,
                replace(drop, load_kg=load),
                replace(options, seed=options.seed + i),
            )
            bags.append(bag)
    return bags
