"""``./ipfric run``: one closed-loop run of the ROS 2 nodes (simulator, controller, recorder) in a fresh
ROS domain on loopback, recorded to a rosbag2 MCAP directory (:mod:`ipfric_core.run.runner`).

SIGINT, SIGTERM and SIGHUP stop the run cleanly and keep the bag."""
from __future__ import annotations

import signal
import sys

from ..run.runner import Run
from ..run.scenario import DEFAULT_SCENARIO, TIME_MODES
from .output import output_dir, print_json

__all__ = ['NAME', 'HELP', 'add_arguments', 'main']

NAME = 'run'
HELP = ('closed-loop run of the ROS 2 nodes (simulator, controller, recorder) in a fresh ROS domain on loopback, '
        'recorded to a rosbag2 MCAP directory')


def add_arguments(r) -> None:
    r.add_argument('--config', default=str(DEFAULT_SCENARIO),
                   help='scenario parameter file (sim_node / controller_node sections), or the name of a shipped '
                        'one (default, realtime, fig7_old_gain_exponential, ...; default %(default)s)')
    r.add_argument('--duration', type=float, default=None,
                   help='simulated seconds (default: the file\'s sim_node duration; 0 = until Ctrl-C)')
    r.add_argument('--out', required=True, help='output directory: bag/, scenario.yaml, logs/, summary.json')
    r.add_argument('--domain', type=int, default=None,
                   help='ROS_DOMAIN_ID (default: a free one in 1..232); rigs in different --namespace share one')
    r.add_argument('--namespace', default=None,
                   help='ROS namespace of the rig (e.g. /rig1): its topics, clock and nodes, and the bag\'s topics')
    r.add_argument('--time-mode', choices=TIME_MODES, default=None,
                   help='lockstep (deterministic, as fast as the loop goes) or realtime (1 sample per period of '
                        'wall time); default: the scenario\'s')
    r.add_argument('--timeout', type=float, default=None, help='stop the run after this many wall seconds')


def main(args) -> int:
    output_dir(args.out)
    def to_interrupt(_signum, _frame):
        raise KeyboardInterrupt
    # explicit: a shell without job control starts background commands with SIGINT ignored
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):   # SIGHUP: the terminal closed
        signal.signal(sig, to_interrupt)
    r = Run(args.config, args.out, args.duration, domain=args.domain, timeout=args.timeout, namespace=args.namespace,
            time_mode=args.time_mode)
    try:
        r.start()
    except KeyboardInterrupt:
        r.kill()
        return 130
    except FileNotFoundError as exc:
        print(f'ipfric run: {exc}', file=sys.stderr)
        return 1
    if not args.json:
        where = f'ROS domain {r.domain}' + ('' if r.namespace == '/' else f', namespace {r.namespace}')
        print(f'ipfric run: {args.config} -> {args.out} ({where}, DDS on loopback); '
              f'Ctrl-C stops the run and keeps the bag', file=sys.stderr)
    res = r.wait()
    if args.json:
        print_json(res.to_dict())
    else:
        print(res.summary())
    for f in res.failures + res.faults:
        print(f'ipfric run: {f}', file=sys.stderr)
    return res.exit_code
