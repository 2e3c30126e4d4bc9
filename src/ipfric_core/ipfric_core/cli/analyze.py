"""``./ipfric analyze``: recorded runs (bags) and rig logs, offline, no ROS.

Exit code 0: every bag intact and complete; 1: a bag truncated or damaged, or holding an
incomplete run (no end event, fewer messages than the simulator published; what was read is
analysed, the loss stated); 2: an input refused (not an MCAP file, no bag)."""
from __future__ import annotations

import math
from pathlib import Path

from ..analysis.recorded_run import analyze_log, analyze_run, overlay_runs
from ..analysis.records import ANGLE_ZEROS, is_log, parse_columns
from ..physics.params import ConfigError
from .output import output_dir, print_json

__all__ = ['NAME', 'HELP', 'add_arguments', 'main', 'print_run_analysis']

NAME = 'analyze'
HELP = ('classify recorded runs (settled, limit cycle, irregular, growing, fallen): amplitude, period, sticking, '
        'plots; reads rosbag2 directories, run directories or .mcap files without ROS, and rig logs (.csv, .mat as '
        'identify reads them) per balanced stretch')


def add_arguments(a) -> None:
    a.add_argument('runs', nargs='+', help='run directory, rosbag2 directory, .mcap file, or a rig log .csv/.mat')
    a.add_argument('--plots', default='runs/analysis', help='directory for PNG figures (default %(default)s)')
    a.add_argument('--no-plots', action='store_true', help='numbers only')
    a.add_argument('--namespace', default=None,
                   help='the rig to read in a bag that holds several (e.g. /rig1); default: the bag\'s only one')
    a.add_argument('--columns', help='rig log: CSV column mapping, e.g. t=time_s,x=cart_m,voltage=u_V,theta=angle_rad')
    a.add_argument('--angle-zero', choices=ANGLE_ZEROS, default='auto',
                   help='rig log: where its angle is zero (default %(default)s: hanging if mostly far from upright)')
    a.add_argument('--max-angle-deg', type=float, default=20.0,
                   help='rig log: balanced while |theta| from upright is below this (default %(default)s deg; '
                   'allowed (0, 90])')
    a.add_argument('--min-balanced-s', type=float, default=2.0,
                   help='rig log: shortest balanced stretch analysed (default %(default)s s; allowed (0, 1e6])')


def print_run_analysis(r: dict) -> None:
    """Readable summary of one :func:`~ipfric_core.analysis.recorded_run.analyze_run` result."""
    rig = '' if r.get('namespace', '/') == '/' else f' (rig {r["namespace"]})'
    print(f'{r["path"]}{rig}: {r["class"]}'
          + (' (TRUNCATED: ' + r['truncation_detail'] + ')' if r['truncated'] else ''))
    for d in r.get('damage', ()):
        print(f'  DAMAGED: {d}')
    if r.get('incomplete'):
        print(f'  INCOMPLETE: {r["incomplete"]}')
    if r.get('class') is None:
        return
    tt = r['transition_time']
    why = f' ({r["end_detail"]})' if r['end_reason'] not in (None, 'END') and r['end_detail'] else ''
    print(f'  {r["samples"]} samples, {r["duration_s"]:.2f} s, end: {r["end_reason"]}{why}; '
          + ('still converging' if tt is None else f'final regime from t = {tt:.3f} s'))
    print(f'  p2p: cart {r["x_p2p"] * 100:.3f} cm, angle {math.degrees(r["theta_p2p"]):.4f} deg; '
          f'cart at rest {100 * r["stick_fraction"]:.0f} % of the window')
    if r['period_crossings'] or r['period_spectrum']:
        pc, ps = r['period_crossings'], r['period_spectrum']
        print(f'  period: {pc and round(pc, 3)} s (zero crossings), {ps and round(ps, 3)} s (spectrum)'
              + ('' if r['periods_agree'] else ': estimates disagree, an irregular oscillation')
              + (f'; {r["frequency"]:.3f} Hz' if r['frequency'] else ''))
    for c in r.get('parameter_changes', ()):
        print(f'  t = {c["t"]:.3f} s: {c["node"]} {c["parameter"]} {c["before"]} -> {c["after"]}')
    for g in r.get('parameter_regimes', ()):
        pc = g['period_crossings']
        print(f'    {g["start"]:7.3f}-{g["end"]:7.3f} s  {g["cls"]:<11}  cart p2p {g["x_p2p"] * 100:.3f} cm, angle p2p '
              f'{math.degrees(g["theta_p2p"]):.4f} deg' + (f', period {pc:.3f} s' if pc else '')
              + (f'  (after {", ".join(g["after"])})' if g['after'] else ''))
    if r.get('samples_without_command') is not None:
        lat = r.get('command_latency_s') or {}
        print(f'  {r["time_mode"]}: {r["samples_without_command"]} samples without a fresh command '
              f'({100 * r["samples_without_command"] / r["samples"]:.2f} %)'
              + (f'; command latency median {lat["median"] * 1e3:.3f} ms, p99 {lat["p99"] * 1e3:.3f} ms, '
                 f'max {lat["max"] * 1e3:.3f} ms' if lat.get('median') is not None else ''))
    if 'figure' in r:
        print(f'  figure: {r["figure"]}')


def print_log_analysis(r: dict) -> None:
    """Readable summary of one :func:`~ipfric_core.analysis.recorded_run.analyze_log` result: a row per regime."""
    print(f'{r["path"]}: {r["samples"]} samples, {r["duration_s"]:.2f} s every {r["sample_period_s"] * 1e3:.3g} ms, '
          f'angle from {r["angle_zero"]}; {len(r["segments"])} balanced stretch(es)')
    for note in r['notes']:
        print(f'  note: {note}')
    for i, seg in enumerate(r['segments'], 1):
        print(f'  stretch {i}: {seg["start"]:.2f}-{seg["end"]:.2f} s, ends {seg["class"]}')
        for g in seg['regimes']:
            pc, ps = g['period_crossings'], g['period_spectrum']
            period = f'; period {pc:.3f} s (crossings), {ps:.3f} s (spectrum)' if pc and ps else ''
            print(f'    {g["start"]:7.2f}-{g["end"]:7.2f} s  {g["cls"]:<11}  cart p2p {g["x_p2p"] * 100:.2f} cm, '
                  f'angle p2p {math.degrees(g["theta_p2p"]):.3f} deg, cart at rest {100 * g["stick_fraction"]:.0f} %'
                  + period)
    if 'figure' in r:
        print(f'  figure: {r["figure"]}')


#: the allowed --max-angle-deg (deg from upright) and --min-balanced-s (s)
MAX_ANGLE_DEG = (0.0, 90.0)
MIN_BALANCED_S = (0.0, 1e6)


def check_thresholds(max_angle_deg: float, min_balanced_s: float) -> None:
    """The rig-log thresholds, checked: 0 < --max-angle-deg <= 90, 0 < --min-balanced-s <= 1e6."""
    for option, v, (lo, hi), unit in (('--max-angle-deg', max_angle_deg, MAX_ANGLE_DEG, 'deg'),
                                      ('--min-balanced-s', min_balanced_s, MIN_BALANCED_S, 's')):
        if not (math.isfinite(v) and lo < v <= hi):
            raise ConfigError(f'{option}: {v!r} is out of range; allowed ({lo:g}, {hi:g}] {unit}')


def main(args) -> int:
    check_thresholds(args.max_angle_deg, args.min_balanced_s)
    output_dir(None if args.no_plots else args.plots, '--plots')
    plots = None if args.no_plots else args.plots
    logs = [p for p in args.runs if is_log(p)]
    if logs and len(logs) != len(args.runs):
        raise ConfigError('give either rig logs (.csv, .mat) or runs (bags), not both')
    if logs:
        columns = parse_columns(args.columns)
        results = [analyze_log(p, columns, args.angle_zero, math.radians(args.max_angle_deg),
                               args.min_balanced_s, plots) for p in logs]
        if args.json:
            print_json({'logs': results})
        for r in [] if args.json else results:
            print_log_analysis(r)
        return 0
    results = [analyze_run(p, plots, namespace=args.namespace) for p in args.runs]
    out: dict = {'runs': results}
    if len(args.runs) > 1 and not args.no_plots:
        out['overlay'] = overlay_runs(args.runs, Path(args.plots) / 'overlay.png', args.namespace)
    code = 1 if any(r['truncated'] or r['damage'] or r['incomplete'] for r in results) else 0
    if args.json:
        print_json(out)
        return code
    for r in results:
        print_run_analysis(r)
    if 'overlay' in out:
        print(f'overlay: {out["overlay"]["figure"]}')
    return code
