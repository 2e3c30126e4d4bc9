"""``./ipfric sweep``: stability maps over the delay tau and the initial angle theta0 (Figures 11-12),
the oscillation against encoder resolution, or the threshold angle (Figure 8b)
(:mod:`ipfric_core.study.sweep`)."""
from __future__ import annotations

import math
import sys

from ..constants import REPO_ROOT
from ..physics.params import ConfigError
from ..study.executor import scheduler_address
from ..study.sweep import figure_study, map_study, parse_range, resolution_report, threshold_report
from ..study.variants import FIGURES, SCALED_SENSORS, SENSORS
from .output import output_dir, print_json, progress_counter

__all__ = ['NAME', 'HELP', 'add_arguments', 'main', 'loop_variant_options']

NAME = 'sweep'
HELP = ('stability map over the delay tau and the initial angle theta0 (Figures 11-12), offline physics core, '
        'parallel and resumable')


def loop_variant_options(parser) -> None:
    """--sensors, --smoothing and --cutoff-hz: the loop a scenario is run as
    (:func:`~ipfric_core.study.variants.variant`)."""
    parser.add_argument('--sensors', choices=SENSORS, default='exact',
                        help='exact states as in the paper\'s simulations, or the scenario\'s encoders '
                        '(default %(default)s)')
    parser.add_argument('--smoothing', choices=('none', 'tanh'), default=None,
                        help='override the friction smoothing')
    parser.add_argument('--cutoff-hz', type=float, default=None,
                        help='override the controller\'s velocity filter corner [Hz] (0 = raw difference; at most 1e4)')


def add_arguments(w) -> None:
    w.add_argument('--config', default=str(REPO_ROOT / 'config' / 'fig9_new_gain_exponential.yaml'),
                   help='base scenario (default %(default)s)')
    w.add_argument('--tau', default='0:0.14:0.005', help='delays [s], start:stop:step or a,b,c (default %(default)s)')
    w.add_argument('--theta0-deg', default='0:12:0.5', help='initial angles [deg] (default %(default)s)')
    w.add_argument('--duration', type=float, default=20.0, help='simulated seconds per cell (default %(default)s)')
    loop_variant_options(w)
    w.add_argument('--workers', type=int, default=None,
                   help='parallel cells in local processes (default: all cores offline, 1 with --ros)')
    w.add_argument('--scheduler', default=None, metavar='ADDRESS',
                   help='run the cells on the Dask cluster whose scheduler listens at ADDRESS '
                        '(e.g. tcp://10.0.0.5:8786; its workers run this project\'s environment), same rows '
                        'as the local processes')
    w.add_argument('--ros', action='store_true',
                   help='run each cell through the ROS 2 nodes in lockstep (bags kept in OUT/ros)')
    w.add_argument('--figure', choices=sorted(FIGURES), default=None,
                   help='the paper\'s Figure 11 (exponential model, sgn and tanh(100 v)) or 12 (dynamic model): '
                        'full theta0 0-12 deg and zoom 0-0.5 deg grids, transition lines on the map; '
                        'ignores --config, --theta0-deg and --smoothing')
    w.add_argument('--resolution-scale', default=None, metavar='SCALES',
                   help='instead of a map: one run per multiple of the scenario\'s encoder counts '
                        '(e.g. 0,0.25,0.5,1,2,4; 0 = exact), oscillation amplitude against resolution (section 6)')
    w.add_argument('--scale-sensor', choices=SCALED_SENSORS, default='angle',
                   help='which encoder --resolution-scale scales (default %(default)s)')
    w.add_argument('--threshold', default=None, metavar='LO,HI',
                   help='instead of a map: bisect the initial angle [rad] between a settling LO and a '
                        'cycling HI (bistability, Figure 8b)')
    w.add_argument('--out', required=True, help='directory for cells.csv, map.png, summary.json')


def print_boundaries(boundaries) -> None:
    for b in boundaries:
        print(f'  theta0 {b["theta0_deg"]:6.3f} deg: settled up to tau = {b["last_settled_tau_s"]}, '
              f'falls from tau = {b["first_fallen_tau_s"]}')


def resolution(args) -> int:
    summary = resolution_report(args.config, args.resolution_scale, args.duration, args.out, args.scale_sensor,
                                args.smoothing, args.cutoff_hz, args.workers, args.scheduler)
    if args.json:
        print_json(summary)
        return 0
    print(f'{"scale":>6} {"angle count":>12} {"class":>12} {"cart p2p":>10} {"angle p2p":>10}')
    for r in summary['rows']:
        print(f'{r["scale"]:6.2f} {math.degrees(r["angle_resolution_rad"]):10.5f}° {r["class"]:>12} '
              f'{r["true_x_p2p_m"] * 1e3:8.3f}mm {math.degrees(r["true_theta_p2p_rad"]):9.4f}°')
    print(f'figure: {summary["figure"]}')
    return 0


def threshold(args) -> int:
    def progress(a, b):
        print(f'[threshold] settles from {a:.4g} rad, cycles from {b:.4g} rad', file=sys.stderr)
    res = threshold_report(args.config, args.threshold, args.duration, args.out, args.sensors, args.smoothing,
                           args.cutoff_hz, None if args.json else progress, args.scheduler)
    if args.json:
        print_json(res)
        return 0
    print(f'converges for theta0 <= {res["settles_below_rad"]:.4g} rad, leaves the equilibrium from '
          f'{res["oscillates_from_rad"]:.4g} rad ({res["runs"]} runs of {args.duration:g} s); that run ends '
          f'{res["hi_class"].replace("_", " ")}, cart p2p {res["hi_x_p2p_m"] * 1e3:.2f} mm over the last 20 s')
    return 0


def figure(args, taus, progress) -> int:
    summary = figure_study(args.figure, taus, args.duration, args.out, args.sensors, args.cutoff_hz, args.workers,
                           progress, None if args.json else (lambda msg: print(f'[sweep] {msg}', file=sys.stderr)),
                           args.ros, args.scheduler)
    if args.json:
        print_json(summary)
        return 0
    for label, grids in summary['variants'].items():
        for gname, g in grids.items():
            print(f'{label}, {gname}:')
            print_boundaries(g['boundaries'])
    print(f'figure: {summary["figure"]}')
    return 0


def main(args) -> int:
    output_dir(args.out)
    if args.scheduler:
        scheduler_address(args.scheduler)
    if args.ros and args.scheduler:
        raise ConfigError('--ros with --scheduler: a ROS cell runs three node processes on this machine; '
                          'drop one of them')
    if args.resolution_scale:
        return resolution(args)
    if args.threshold:
        return threshold(args)
    try:
        taus, ths = parse_range(args.tau), parse_range(args.theta0_deg)
    except ValueError as exc:
        raise ConfigError(f'--tau/--theta0-deg: {exc}') from exc
    progress = None if args.json else progress_counter('sweep')
    if args.figure:
        return figure(args, taus, progress)
    summary = map_study(args.config, taus, ths, args.duration, args.out, args.sensors, args.smoothing,
                        args.cutoff_hz, args.workers, progress, args.ros, args.scheduler)
    if args.json:
        print_json(summary)
        return 0
    print(f'{summary["cells"]} cells: ' + ', '.join(f'{k} {v}' for k, v in summary['counts'].items()))
    print_boundaries(summary['boundaries'])
    print(f'map: {summary["figure"]}\ncells: {summary["csv"]}')
    return 0
