"""``./ipfric demo``: the main job, a closed-loop run of the default scenario through the ROS 2 nodes,
recorded and analysed."""
from __future__ import annotations

import sys

from ..run.demo import demo
from ..run.scenario import DEFAULT_SCENARIO
from .analyze import print_run_analysis
from .output import output_dir, print_json

__all__ = ['NAME', 'HELP', 'add_arguments', 'main']

NAME = 'demo'
HELP = ('the main job: a closed-loop run of the default scenario through the ROS 2 nodes (Figure 7: gain (15) '
        'on the stick-slip plant), recorded and analysed')


def add_arguments(m) -> None:
    m.add_argument('--config', default=str(DEFAULT_SCENARIO), help='scenario parameter file (default %(default)s)')
    m.add_argument('--duration', type=float, default=None, help='simulated seconds (default: the file\'s)')
    m.add_argument('--out', default=None, help='run directory (default runs/demo-<time>)')


def main(args) -> int:
    output_dir(args.out)
    say = None if args.json else (lambda msg: print(f'[demo] {msg}', file=sys.stderr))
    res, summary = demo(args.config, args.out, args.duration, say)
    if summary is None:
        print(res.summary(), file=sys.stderr)
        return res.exit_code
    if args.json:
        print_json(summary)
        return 0
    print(res.summary())
    print()
    print_run_analysis(summary['analysis'])
    print(f'analysis: {summary["file"]}')
    return 0
