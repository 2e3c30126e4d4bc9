"""``./ipfric identify``: friction and undeclared effects from measured data (a run bag, a CSV, an EMPS
.mat), the paper's Tables 5-6, or the closed-loop redesign (:mod:`ipfric_core.ident.identify`)."""
from __future__ import annotations

import math
import sys
from pathlib import Path

from ..analysis.records import parse_columns
from ..design.paperconfig import DEFAULT_DATA
from ..ident.held_out import INIT_SAMPLES
from ..ident.identify import SPLIT_RANGE, identify_record, identify_tables
from ..ident.ladder_report import correlation_lines
from ..ident.redesign import close_the_loop
from ..run.scenario import DEFAULT_SCENARIO
from .output import output_dir, print_json

__all__ = ['NAME', 'HELP', 'add_arguments', 'main']

NAME = 'identify'
HELP = ('identify the cart\'s friction and undeclared effects from measured data (run bag, CSV, EMPS .mat, or '
        '"paper" for Tables 5-6): the declared model and competing hypotheses (refit, laws, plant corrections, '
        'effects) judged by simulation error on validation data, a verdict against the encoders\' floor; '
        'report, export, redesign')


def add_arguments(i) -> None:
    i.add_argument('data', nargs='?', default='paper', help='run directory / bag / .mcap, .csv (t,x,voltage[,theta]), '
                   'EMPS .mat, or "paper" (default %(default)s)')
    i.add_argument('--validation', help='second file for validation (default: the last part of DATA)')
    i.add_argument('--test', help='a held-out file the final model runs free over, from its first --test-init '
                   'readings (the nonlinear benchmarks\' protocol); reports the position RMS error in mm')
    i.add_argument('--test-init', type=int, default=INIT_SAMPLES, help='readings that initialise the --test run '
                   '(default %(default)s, EMPS\'s state_initialization_window_length)')
    i.add_argument('--split', type=float, default=0.6, help='estimation share of DATA when no --validation, in '
                   f'[{SPLIT_RANGE[0]:g}, {SPLIT_RANGE[1]:g}] (default %(default)s)')
    i.add_argument('--base', default='exponential', help='declared friction law: viscous, coulomb, exponential, '
                   'dynamic (the paper\'s values, unless --plant gives them; for a force-input record such as EMPS '
                   'the law its force balance fits) (default %(default)s)')
    i.add_argument('--free', help='known plant constants to fit too, e.g. M,alpha (default: none; they stay '
                   'as declared)')
    i.add_argument('--effects', help='comma-separated candidate effects (default: the whole library)')
    i.add_argument('--plant', help='the declared model: a scenario, a paper-style YAML, or a file with only '
                   'plant: (default: a bag\'s stored scenario, else Table 1; friction: the paper\'s --base law)')
    i.add_argument('--columns', help='CSV column mapping, e.g. t=time_s,x=cart_m,voltage=u_V,theta=angle_rad')
    i.add_argument('--cart-alone', action='store_true', help='ignore the angle of the record (pendulum off)')
    i.add_argument('--tables', default=str(Path(DEFAULT_DATA) / 'paper'), help='directory of Tables 5-6 '
                   '(default %(default)s)')
    i.add_argument('--out', default='runs/identify', help='report directory (default %(default)s)')
    i.add_argument('--no-plots', action='store_true', help='no PNG figures')
    i.add_argument('--time-limit', type=float, metavar='SECONDS', help='start no round of the ladder after the '
                   'first once it has run this long; the verdict says where it stopped (default: no limit)')
    i.add_argument('--export', help='write the identified plant and the gain designed on it as a scenario YAML')
    i.add_argument('--scenario', default=str(DEFAULT_SCENARIO),
                   help='settings, Q and R for --export (default %(default)s)')
    i.add_argument('--rig', help='with --export: also write <export>_on_rig.yaml, this scenario\'s rig with '
                   'the new gain')
    i.add_argument('--loop', metavar='SCENARIO', help='closed-loop redesign offline: run SCENARIO, identify on '
                   'its measured data, redesign, run again; prints the amplitudes before and after')
    i.add_argument('--duration', type=float, default=20.0, help='--loop: simulated seconds per run '
                   '(default %(default)s)')


def loop(args) -> int:
    out = close_the_loop(args.loop, args.out, args.duration, args.base, not args.no_plots)
    if args.json:
        print_json(out)
        return 0
    b, a = out['before'], out['after']
    print(f'{args.loop}: gain {[round(k, 2) for k in out["gain_before"]]} -> {b["class"]}, cart p2p '
          f'{b["x_p2p_m"] * 1000:.2f} mm, angle p2p {math.degrees(b["theta_p2p_rad"]):.3f} deg')
    idf = out['identified']
    print(f'identified: {idf["base_model"]} + {", ".join(idf["effects_added"]) or "nothing"}; '
          + ', '.join(f'{k} {v:.4g}' for k, v in idf['friction'].items() if not isinstance(v, str)))
    print(f'redesigned gain {[round(k, 2) for k in out["gain_after"]]} -> {a["class"]}, cart p2p '
          f'{a["x_p2p_m"] * 1000:.2f} mm, angle p2p {math.degrees(a["theta_p2p_rad"]):.3f} deg')
    print(f'cart amplitude {b["x_p2p_m"] * 1000:.2f} mm before, {a["x_p2p_m"] * 1000:.2f} mm after; '
          f'report {out["report"]}; scenarios {out["export"]["scenario"]}, {out["export"]["on_rig"]}')
    return 0


def tables(args) -> int:
    rep = identify_tables(args.tables, args.plant)
    if args.json:
        print_json(rep)
        return 0
    print('Tables 5 and 6 through the force balance (coulomb effect, F_N = M g):')
    for k in ('mu_c', 'eps', 'mu_s'):
        print(f'  {k:<5} {rep[k]:.5f} +/- {rep[k + "_std"]:.5f}')
    print(f'  sliding residual RMS {rep["sliding_rms_N"]:.4f} N, breakaway residual RMS '
          f'{rep["breakaway_rms_N"]:.4f} N, curvature of the residual over the velocity range '
          f'{rep["residual_curvature_N"]:+.4f} N')
    return 0


def fmt_param(p: dict) -> str:
    std = f' +/- {p["std"]:.2g}' if p['std'] is not None and math.isfinite(p['std']) else ''
    return f'{p["value"]:.4g}{std} {p["unit"]}'.rstrip()


def print_ladder(r: dict) -> None:
    """The ladder's steps, notes, final parameters and correlations."""
    print(f'{r["data"]["estimation"]} / {r["data"]["validation"]}: effects added: '
          f'{", ".join(r["effects_added"]) or "none"}')
    for note in r['data']['notes']:
        print(f'  data: {note}')
    for s in r['ladder']:
        v = s['validation']
        print(f'  {s["step"]:<14} validation simulation error {v["x_rms_counts"]:8.3g} counts ({v["x_percent"]:.3g} %)'
              + (f', angle {v["theta_rms_counts"]:.3g} counts' if 'theta_rms_counts' in v else ''))
        for n in s['notes']:
            print(f'    {n}')
    last = r['ladder'][-1]
    print('  ' + ', '.join(f'{p["name"]} {fmt_param(p)}' for p in last['params'] if p['fitted']))
    for line in correlation_lines(last, {p['name']: p['unit'] for p in last['params']}):
        print(f'  {line}')
    rough = [p['name'] for p in last['params'] if p.get('rough')]
    if rough:
        print(f'  the simulated error is rough in {", ".join(rough)}: their errors come from a scan of the error '
              f'along each')
    for rd in r['rounds']:
        ru = rd['runner_up']
        if ru:
            print(f'  round {rd["round"]}: kept {rd["kept"] or "nothing"}; runner-up {ru["hypothesis"]} '
                  f'({ru["validation_x_rms_counts"]:.3g} counts)')
    for f in r.get('force_error', []):
        print(f'  {f["step"]:<14} relative force error: estimation {f["estimation"]["relative_percent"]:.3f} %, '
              f'validation {f["validation"]["relative_percent"]:.3f} %')
    if 'test' in r:
        t = r['test']
        print(f'  test {t["record"]}: run free from its first {t["init_samples"]} readings, position RMS error '
              f'{t["rmse_mm"]:.4g} mm over {t["samples"]} readings')
    v = r['verdict']
    print(f'  {v["reason"]}')
    for t in [] if v['explained'] else v.get('largest_left', []):
        print(f'    left: {t["hypothesis"]} lowers it {t["validation_gain_percent"]:.3g} %, refused: '
              f'{"; ".join(t["refused"])}')


def main(args) -> int:
    output_dir(args.out)
    if args.loop:
        return loop(args)
    if args.data == 'paper':
        return tables(args)
    say = None if args.json else (lambda msg: print(msg, file=sys.stderr))
    r = identify_record(args.data, args.out, args.plant, args.base, args.free, args.effects,
                        parse_columns(args.columns), args.cart_alone, args.validation, args.split,
                        not args.no_plots, args.export, args.scenario, args.rig, say, args.test, args.test_init,
                        args.time_limit)
    if args.json:
        print_json(r)
        return 0
    print_ladder(r)
    print(f'  report {r["files"]["report"]}')
    if 'export' in r:
        print(f'  exported {r["export"]["scenario"]}' + (f' and {r["export"]["on_rig"]}' if 'on_rig' in r['export']
                                                         else ''))
    return 0
