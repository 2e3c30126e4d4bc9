"""``./ipfric bench``: every benchmark beside its reference (``bench/`` of the checkout), table in
``bench/RESULTS.md``."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from ..constants import REPO_ROOT
from ..physics.params import ConfigError

__all__ = ['NAME', 'HELP', 'add_arguments', 'main']

NAME = 'bench'
HELP = ('benchmarks beside their references (scipy, MuJoCo, raw rclpy): offline closed loop, Figure-11 sweep, ROS '
        'lockstep and realtime loops, analyze, identify, the identification campaign; table and bench/RESULTS.md')
RESULTS = REPO_ROOT / 'bench' / 'RESULTS.md'
QUICK_RESULTS = REPO_ROOT / 'runs' / 'bench-quick' / 'RESULTS.md'


def add_arguments(b) -> None:
    b.add_argument('--quick', action='store_true', help='tiny sizes: check that every benchmark runs (no targets)')
    b.add_argument('--realtime-duration', type=float, default=600.0,
                   help='seconds of the realtime ROS run whose bag analyze reads (default %(default)s)')
    b.add_argument('--campaign-cases', type=int, default=200,
                   help='cases of the randomised identification campaign (default %(default)s, about two hours on '
                        'two cores; --quick: one)')
    b.add_argument('--results', default=None, help=f'where to write the table (default {RESULTS}, '
                   f'{QUICK_RESULTS} with --quick)')


def main(args) -> int:
    """The benchmarks of the checkout's ``bench/`` in a process of their own (``python -m bench.run``:
    the package does not import the checkout)."""
    if not (REPO_ROOT / 'bench' / 'run.py').is_file():
        raise ConfigError(f'bench: {REPO_ROOT / "bench"} is not there; the benchmarks run from a checkout')
    if args.campaign_cases < 1:
        raise ConfigError(f'--campaign-cases: {args.campaign_cases} is out of range; allowed: 1 or more')
    results = Path(args.results) if args.results else (QUICK_RESULTS if args.quick else RESULTS)
    cmd = [sys.executable, '-m', 'bench.run', '--realtime-duration', str(args.realtime_duration),
           '--campaign-cases', str(args.campaign_cases), '--results', str(results.resolve())]
    cmd += (['--quick'] if args.quick else []) + (['--json'] if args.json else [])
    return subprocess.run(cmd, cwd=REPO_ROOT).returncode
