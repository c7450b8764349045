"""The live graph soaked on a looping bag: does the diagnosis node diagnose every pass?

``python -m lumpbeam_lab.graph.soak [--minutes 10] [--duration 12] [--sim-time] [--out DIR]``

Synthesizes a drop-test bag, asks ``lumpbeam diagnose`` for its verdict, then starts the
drop-test chain (``launch/drop_test.launch.yaml`` through ``lumpbeam launch``) and plays the
bag in a loop (``lumpbeam play --loop``, on wall time unless ``--sim-time``) for the given
minutes. A probe counts the passes (each release on ``/tip_load``), the diagnoses the node
made (its ``diagnoses`` count) and their verdicts, and the statuses that repeat a verdict as
current after the clock went back. It prints one table and exits 1 when a complete pass went
undiagnosed, a live verdict disagreed with the offline one, or a stale verdict was repeated
as current.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

from lumpbeam_ros.apps.demo.graph import ProcessGraph, python_command
from lumpbeam_ros.apps.demo.run import CLI_MODULE
from lumpbeam_ros.base.interface import DIAGNOSIS_STATUS, MODEL_DISCREPANCY, TIP_LOAD
from lumpbeam_ros.base.resources import share_dir

#: The diagnosis's verdict on a pass is due this long after the pass's ring-down ends, s.
VERDICT_ALLOWANCE_S = 30.0
#: DiagnosticStatus levels.
STALE = 3


@dataclass
class Tally:
    """What the probe heard."""

    releases: list[float] = field(default_factory=list)  # wall time of each load drop
    load_kg: float = 0.0
    diagnoses: dict[int, str] = field(default_factory=dict)  # count -> missing_effect
    diagnosed_at: dict[int, float] = field(default_factory=dict)
    statuses: Counter[int] = field(default_factory=Counter)
    stale_repeats: int = 0


def _offline_verdict(bag: Path, folder: Path) -> str:
    out = folder / 'diagnose.json'
    subprocess.run(
        python_command(CLI_MODULE, 'diagnose', str(bag), '--json', str(out)),
        check=True,
        stdout=subprocess.DEVNULL,
    )
    return str(json.loads(out.read_text())['missing_effect'])


def _listen(graph: ProcessGraph, seconds: float, tally: Tally) -> None:
    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from std_msgs.msg import Float64

    def on_load(msg: Float64) -> None:
        if msg.data < tally.load_kg:
            tally.releases.append(time.monotonic())
        tally.load_kg = msg.data

    def on_status(msg: DiagnosticArray) -> None:
        for status in msg.status:
            if status.name != DIAGNOSIS_STATUS:
                continue
            values = {kv.key: kv.value for kv in status.values}
            tally.statuses[status.level[0]] += 1
            count = int(values.get('diagnoses', '0'))
            if count and count not in tally.diagnoses and 'missing_effect' in values:
                tally.diagnoses[count] = values['missing_effect']
                tally.diagnosed_at[count] = time.monotonic()
            if status.message.startswith('the clock went back') and status.level[0] != STALE:
                tally.stale_repeats += 1

    context = Context()
    rclpy.init(context=context, domain_id=graph.domain_id)
    latched = QoSProfile(
        depth=1,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )
    try:
        probe = Node('lumpbeam_soak_probe', context=context)
        probe.create_subscription(Float64, TIP_LOAD, on_load, latched)
        probe.create_subscription(DiagnosticArray, MODEL_DISCREPANCY, on_status, 100)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(probe)
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            graph.check_running()
            executor.spin_once(timeout_sec=0.1)
        executor.shutdown()
        probe.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)


def soak(minutes: float, duration_s: float, sim_time: bool, folder: Path) -> int:
    """Runs the soak and prints its table.

    Returns:
        0 when every complete pass was diagnosed as offline and nothing stale was repeated.
    """
    bag = folder / 'drop.mcap'
    subprocess.run(
        python_command(
            CLI_MODULE, 'synth', str(bag), '--force',
            '--duration', f'{duration_s:g}',
        ),
        check=True,
        stdout=subprocess.DEVNULL,
    )  # fmt: skip
    offline = _offline_verdict(bag, folder)
    launch = share_dir() / 'launch' / 'drop_test.launch.yaml'
    tally = Tally()
    with ProcessGraph(folder / 'logs') as graph:
        graph.start(
            'launch',
            python_command(
                CLI_MODULE, 'launch', str(launch),
                f'use_sim_time:={"true" if sim_time else "false"}',
            ),
        )  # fmt: skip
        graph.start(
            'play',
            python_command(CLI_MODULE, 'play', str(bag), '--loop', '--delay', '5'),
        )
        started = time.monotonic()
        _listen(graph, minutes * 60.0, tally)
    # A pass's verdict can only be due once its ring-down ended and the allowance passed.
    due = [t for t in tally.releases if t < started + minutes * 60.0 - VERDICT_ALLOWANCE_S]
    verdicts = Counter(tally.diagnoses.values())
    wrong = sum(n for verdict, n in verdicts.items() if verdict != offline)
    print(f'soak: {minutes:g} min of a {duration_s:g} s bag looping on '
          f'{"/clock" if sim_time else "wall time"}')  # fmt: skip
    print(f'  passes (releases heard)         {len(tally.releases)}')
    print(f'  passes due a verdict            {len(due)}')
    print(f'  diagnoses                       {len(tally.diagnoses)}')
    print(f'  live verdicts                   {dict(verdicts)}')
    print(f'  offline verdict                 {offline}')
    print(f'  statuses by level               {dict(sorted(tally.statuses.items()))}')
    print(f'  stale verdicts repeated as new  {tally.stale_repeats}')
    ok = len(tally.diagnoses) >= len(due) and wrong == 0 and tally.stale_repeats == 0
    print(f'  result                          {"pass" if ok else "FAIL"}')
    return 0 if ok else 1


def main(argv: list[str] | None = None) -> int:
    """Command line: see the module's docstring."""
    parser = argparse.ArgumentParser(prog='python -m lumpbeam_lab.graph.soak', description=__doc__)
    parser.add_argument('--minutes', type=float, default=10.0)
    parser.add_argument('--duration', type=float, default=12.0, help='the bag, s')
    parser.add_argument('--sim-time', action='store_true', help='play with /clock')
    parser.add_argument('--out', type=Path, help='folder for the bag and logs (kept)')
    args = parser.parse_args(argv)
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        return soak(args.minutes, args.duration, args.sim_time, args.out)
    with tempfile.TemporaryDirectory() as folder:
        return soak(args.minutes, args.duration, args.sim_time, Path(folder))


if __name__ == '__main__':
    sys.exit(main())
