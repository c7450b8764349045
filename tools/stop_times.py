"""Prints how long each node and long command takes to stop after SIGTERM and SIGINT.

Usage: ``python tools/stop_times.py [--busy N] [--delay S] [--only NAME ...]``.

Every process is started as its console script starts it (``lumpbeam_ros.nodes.scripts``,
``lumpbeam_ros.apps.cli.script``), given work (the nodes hear a looping ``lumpbeam play`` of a
drop test, the camera node tracks a filmed bag, the commands get inputs that keep them busy
for longer than ``--delay``), signalled ``--delay`` seconds after its start, and timed from
the signal to its exit. ``--busy N`` runs N busy loops beside it (a loaded machine). A row
whose process had already ended when the signal came says so. The inputs are written to a
temporary folder first (about a minute).
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

NODES = ('camera', 'identifier', 'simulator', 'diagnosis', 'shaper')
COMMANDS = ('play', 'record', 'synth', 'analyze', 'diagnose', 'campaign')
SIGNALS = (signal.SIGTERM, signal.SIGINT)
#: Longest wait for an exit after the signal, s.
TIMEOUT_S = 30.0


def _script(kind: str, name: str) -> list[str]:
    if kind == 'node':
        code = (
            f'import sys; from lumpbeam_ros.nodes.scripts import {name}_node as f; sys.exit(f())'
        )
    else:
        code = 'import sys; from lumpbeam_ros.apps.cli.script import lumpbeam as f; sys.exit(f())'
    return [sys.executable, '-c', code]


def _lumpbeam(*args: str) -> None:
    subprocess.run([*_script('cli', ''), *args], check=True, stdout=subprocess.DEVNULL)


def prepare(folder: Path) -> dict[str, list[str]]:
    """Writes the inputs; returns each target's arguments."""
    _lumpbeam('synth', str(folder / 'drop'), '--duration', '12')
    _lumpbeam('synth', str(folder / 'long'), '--duration', '2500')
    _lumpbeam('synth', str(folder / 'filmed'), '--duration', '12', '--images',
              '--image-size', '320x240')  # fmt: skip
    drop, long, filmed = (str(folder / n) for n in ('drop', 'long', 'filmed'))
    return {
        'camera': ['--ros-args', '-p', f'bag_path:={filmed}', '-p', 'wait_for_subscriber_s:=0'],
        'identifier': ['--ros-args', '-p', 'use_sim_time:=true'],
        'simulator': [],
        'diagnosis': [],
        'shaper': [],
        'play': ['play', drop, '--loop'],
        'record': ['record', str(folder / 'recorded'), '/tip_pose', '/tip_load'],
        'synth': [
            'synth',
            str(folder / 'synth_out'),
            '--duration',
            '60',
            '--images',
            '--image-size',
            '320x240',
        ],  # fmt: skip
        'analyze': ['analyze', long],
        'diagnose': ['diagnose', drop],
        'campaign': ['campaign', '--out', str(folder / 'campaign'), '--diagnose', drop, long],
    }


def stop_time(argv: list[str], sig: signal.Signals, delay_s: float, env: dict[str, str]) -> str:
    """Starts, signals after ``delay_s``, returns ``'seconds (exit code)'`` as printed."""
    process = subprocess.Popen(argv, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    time.sleep(delay_s)
    if process.poll() is not None:
        return f'ended before ({process.returncode})'
    sent = time.perf_counter()
    process.send_signal(sig)
    try:
        _, stderr = process.communicate(timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        process.kill()
        process.communicate()
        return f'> {TIMEOUT_S:g} (killed)'
    took = time.perf_counter() - sent
    traceback = ' TRACEBACK' if b'Traceback' in stderr else ''
    return f'{took:.2f} ({process.returncode}){traceback}'


def main() -> int:
    """Prints the table (markdown) of stop times: seconds after the signal (exit code)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--busy', type=int, default=0, help='busy loops beside (0)')
    parser.add_argument('--delay', type=float, default=5.0, help='signal after this long, s')
    parser.add_argument('--only', nargs='+', default=[*NODES, *COMMANDS])
    parser.add_argument('--domain', type=int, default=int(os.environ.get('ROS_DOMAIN_ID', 77)))
    args = parser.parse_args()
    env = dict(
        os.environ, ROS_DOMAIN_ID=str(args.domain), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST'
    )
    folder = Path(tempfile.mkdtemp(prefix='stop_times_'))
    busy: list[subprocess.Popen[bytes]] = []
    player = None
    try:
        targets = prepare(folder)
        player = subprocess.Popen(
            [*_script('cli', ''), 'play', str(folder / 'drop'), '--loop'],
            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        busy = [
            subprocess.Popen([sys.executable, '-c', 'while True: pass']) for _ in range(args.busy)
        ]
        print(f'busy loops: {args.busy}, signal {args.delay:g} s after start; '
              f'load average {os.getloadavg()[0]:.1f}')  # fmt: skip
        print(f'| target | {" | ".join(s.name for s in SIGNALS)} |')
        print(f'|---|{"---|" * len(SIGNALS)}')
        for name in args.only:
            kind = 'node' if name in NODES else 'cli'
            cells = []
            for sig in SIGNALS:
                for leftover in ('recorded', 'synth_out', 'campaign'):
                    shutil.rmtree(folder / leftover, ignore_errors=True)
                argv = [*_script(kind, name), *targets[name]]
                # The player only for the nodes: a command plays its own input.
                cells.append(stop_time(argv, sig, args.delay, env))
            print(f'| {name} | {" | ".join(cells)} |', flush=True)
        print(f'load average at the end {os.getloadavg()[0]:.1f}')
    finally:
        for process in [*busy, *([player] if player else [])]:
            process.send_signal(signal.SIGTERM)
            process.wait()
        shutil.rmtree(folder, ignore_errors=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
