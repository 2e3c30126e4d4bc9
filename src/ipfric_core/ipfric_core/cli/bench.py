"""``./ipfric bench``: every benchmark beside its reference (``bench/`` of the checkout), table in
``bench/RESULTS.md``."""
from __future__ import annotations

import sys
from pathlib import Path

from ..constants import REPO_ROOT
from .output import print_json

__all__ = ['NAME', 'HELP', 'add_arguments', 'main']

NAME = 'bench'
HELP = ('benchmarks beside their references (scipy, MuJoCo, raw rclpy): offline closed loop, Figure-11 sweep, ROS '
        'lockstep and realtime loops, analyze, identify; table and bench/RESULTS.md')
RESULTS = REPO_ROOT / 'bench' / 'RESULTS.md'
QUICK_RESULTS = REPO_ROOT / 'runs' / 'bench-quick' / 'RESULTS.md'


def add_arguments(b) -> None:
    b.add_argument('--quick', action='store_true', help='tiny sizes: check that every benchmark runs (no targets)')
    b.add_argument('--realtime-duration', type=float, default=600.0,
                   help='seconds of the realtime ROS run whose bag analyze reads (default %(default)s)')
    b.add_argument('--results', default=None, help=f'where to write the table (default {RESULTS}, '
                   f'{QUICK_RESULTS} with --quick)')


def main(args) -> int:
    sys.path.insert(0, str(REPO_ROOT))      # bench/ is part of the checkout, not of the package
    from bench.run import run_all
    results = Path(args.results) if args.results else (QUICK_RESULTS if args.quick else RESULTS)
    out = run_all(args.quick, args.realtime_duration, results, progress=(lambda msg: print(msg, file=sys.stderr)))
    if args.json:
        print_json(out)
        return 0
    print(out['table'])
    print(f'written: {out["results"]}')
    return 0
