"""Command line of ipfric: ``./ipfric <command> [--json]``."""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from .params import ConfigError
from .paperconfig import DEFAULT_CONFIG, DEFAULT_DATA, REPO_ROOT, load_paper_config


def _print_json(obj) -> None:
    json.dump(obj, sys.stdout, indent=2, default=float)
    sys.stdout.write('\n')


def _row(label, entry, fmt='{:.4f}') -> str:
    ours, ref = entry['ipfric'], entry['paper']
    if isinstance(ours, list):
        ours = '[' + ', '.join(fmt.format(v) for v in ours) + ']'
        ref = '[' + ', '.join(fmt.format(v) for v in ref) + ']'
    else:
        ours, ref = fmt.format(ours), fmt.format(ref)
    return f'  {label:<34} ipfric {ours}\n  {"":<34} paper  {ref}'


def _eig_text(pairs) -> str:
    return ', '.join(f'{re:.4f}' + (f'{im:+.4f}i' if im else '') for re, im in pairs)


def cmd_design(args) -> int:
    from .reports import design_report
    cfg = load_paper_config(args.config)
    rep = design_report(cfg, Path(args.data) / 'paper')
    if args.json:
        _print_json(rep)
        return 0
    print(f'LQR gains, V = +K x, Q = diag{cfg.Q}, R = {cfg.R:g}  ({args.config})')
    for name, e in rep['gains'].items():
        print(_row(f'{name} model, eq. {e["equation"]}', e))
        if 'full_gain_with_z' in e:
            print(f'  {"":<34} full gain incl. z (not measured): '
                  + ', '.join(f'{v:.4f}' for v in e['full_gain_with_z']))
    print('Closed-loop eigenvalues, dynamic friction model (eq. 21)')
    for label, e in rep['eigenvalues'].items():
        print(f'  {label:<34} ipfric {_eig_text(e["ipfric"])}\n  {"":<34} paper  {_eig_text(e["paper"])}')
    print('Controllability rank: ' + ', '.join(f'{k} {v["rank"]}/{v["n_states"]}'
                                               for k, v in rep['controllability_rank'].items()))
    fe = rep['friction_estimates']
    print('Friction from the cart-alone experiments (appendix)')
    print(f'  mu_s (Table 6)                      ipfric {fe["mu_s"]["ipfric"]:.5f} +/- {fe["mu_s"]["std"]:.5f}'
          f'   paper {fe["mu_s"]["paper"]}')
    for key in ('table5_row_averages', 'table5_individual_runs'):
        e = fe[key]
        print(f'  mu_c, eps ({key.replace("table5_", "Table 5, ").replace("_", " ")}) '
              f'least squares {e["mu_c"]:.5f} +/- {e["mu_c_std"]:.5f}, {e["eps"]:.4f} +/- {e["eps_std"]:.4f};'
              f' pairwise mean {e["pairwise_mean"]["mu_c"]:.5f}, {e["pairwise_mean"]["eps"]:.4f}')
    print(f'  paper                               mu_c {fe["paper"]["mu_c"]}, eps {fe["paper"]["eps"]}')
    for s in fe['table5_runs_set_aside']:
        print(f'  set aside: {s["value_mps"]} m/s at {s["voltage_V"]} V (row average {s["row_average_mps"]})')
    return 0


def cmd_stability(args) -> int:
    from .reports import stability_report
    rep = stability_report(load_paper_config(args.config))
    if args.json:
        _print_json(rep)
        return 0
    rh = rep['routh_hurwitz_gain_15_exponential']
    print('Gain (15) on the exponential model, sgn(v) ~ tanh(delta v), eq. (19):')
    print(_row('two RHP roots for delta >', rh['unstable_above_delta'], '{:.2f}'))
    print(_row('complex RHP pair up to delta', rh['complex_pair_until_delta'], '{:.2f}'))
    print('Critical delay tau_c of eq. (27):')
    for name, e in rep['critical_delay_s'].items():
        print(_row(f'{name}', e))
        if 'with_full_gain_incl_z' in e:
            print(f'  {"":<34} with the full gain incl. z: {e["with_full_gain_incl_z"]:.4f}')
    return 0


def cmd_demo(args) -> int:
    """The README's main job: the paper's design and stability report."""
    if args.json:
        from .reports import design_report, stability_report
        cfg = load_paper_config(args.config)
        _print_json({'design': design_report(cfg, Path(args.data) / 'paper'),
                     'stability': stability_report(cfg)})
        return 0
    rc = cmd_design(args)
    print()
    return rc or cmd_stability(args)


def cmd_run(args) -> int:
    from .runner import cmd_run as run
    return run(args)


def cmd_analyze(args) -> int:
    from .analysis import analyze_run, overlay_runs
    results = [analyze_run(p, None if args.no_plots else args.plots) for p in args.runs]
    out = {'runs': results}
    if len(args.runs) > 1 and not args.no_plots:
        out['overlay'] = overlay_runs(args.runs, Path(args.plots) / 'overlay.png')
    if args.json:
        _print_json(out)
        return 0
    for r in results:
        print(f'{r["path"]}: {r["class"]}' + (' (TRUNCATED: ' + r['truncation_detail'] + ')' if r['truncated'] else ''))
        if r.get('class') is None:
            continue
        print(f'  {r["samples"]} samples, {r["duration_s"]:.2f} s, end: {r["end_reason"]}; '
              f'transition at {r["transition_time"] if r["transition_time"] is None else round(r["transition_time"], 3)} s')
        print(f'  p2p: cart {r["x_p2p"] * 100:.3f} cm, angle {math.degrees(r["theta_p2p"]):.4f} deg; '
              f'cart at rest {100 * r["stick_fraction"]:.0f} % of the window')
        if r['period_crossings'] or r['period_spectrum']:
            pc, ps = r['period_crossings'], r['period_spectrum']
            print(f'  period: {pc and round(pc, 3)} s (zero crossings), {ps and round(ps, 3)} s (spectrum)')
        if 'figure' in r:
            print(f'  figure: {r["figure"]}')
    if 'overlay' in out:
        print(f'overlay: {out["overlay"]["figure"]}')
    return 0


def cmd_sweep(args) -> int:
    from dataclasses import replace

    from .plots import stability_map
    from .scenario import load_scenario
    from .sweep import boundaries, grid, parse_range, print_progress, sweep
    base = load_scenario(args.config)
    if args.sensors == 'exact':
        base = replace(base, sim=replace(base.sim, cart_resolution=0.0, angle_resolution=0.0))
    if args.smoothing:
        base = replace(base, friction=base.friction.replace(smoothing=args.smoothing))
    try:
        taus, ths = parse_range(args.tau), parse_range(args.theta0_deg)
    except ValueError as exc:
        raise ConfigError(f'--tau/--theta0-deg: {exc}') from exc
    out = Path(args.out)
    rows = sweep(base, taus, ths, args.duration, out, args.workers, None if args.json else print_progress)
    title = f'{Path(args.config).stem}: {base.friction.model}' + (
        f', tanh({base.friction.delta:g} v)' if base.friction.smoothing == 'tanh' else '')
    fig = stability_map(taus, ths, grid(rows, taus, ths), title, out / 'map.png')
    summary = {'config': args.config, 'sensors': args.sensors, 'duration_s': args.duration,
               'cells': len(rows), 'figure': str(fig), 'csv': str(out / 'cells.csv'),
               'counts': {c: sum(r['class'] == c for r in rows) for c in ('settled', 'limit_cycle', 'growing', 'fallen')},
               'boundaries': boundaries(rows, taus, ths)}
    (out / 'summary.json').write_text(json.dumps(summary, indent=2, default=float))
    if args.json:
        _print_json(summary)
        return 0
    print(f'{len(rows)} cells: ' + ', '.join(f'{k} {v}' for k, v in summary['counts'].items()))
    for b in summary['boundaries']:
        print(f'  theta0 {b["theta0_deg"]:6.3f} deg: settled up to tau = {b["last_settled_tau_s"]}, '
              f'falls from tau = {b["first_fallen_tau_s"]}')
    print(f'map: {fig}\ncells: {out / "cells.csv"}')
    return 0


def cmd_bench(args) -> int:
    sys.path.insert(0, str(REPO_ROOT))
    from bench.run import run_all
    results = Path(args.results) if args.results else (
        REPO_ROOT / 'runs' / 'bench-quick' / 'RESULTS.md' if args.quick else REPO_ROOT / 'bench' / 'RESULTS.md')
    out = run_all(args.quick, args.realtime_duration, results,
                  progress=(lambda msg: print(msg, file=sys.stderr)))
    if args.json:
        _print_json(out)
        return 0
    print(out['table'])
    print(f'written: {out["results"]}')
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog='ipfric', description='Friction and the inverted pendulum: '
                                'design, simulation, ROS 2 closed loop and analysis.')
    sub = p.add_subparsers(dest='command', required=True, metavar='command')

    def add(name, func, help_text):
        sp = sub.add_parser(name, help=help_text, description=help_text)
        sp.add_argument('--json', action='store_true', help='print a machine-readable result on stdout')
        sp.set_defaults(func=func)
        return sp

    d = add('design', cmd_design, 'LQR gains of the paper (15), (23), (25), eigenvalues and '
            'friction estimates, computed beside the printed values')
    d.add_argument('--config', default=str(DEFAULT_CONFIG), help='paper parameter YAML (default %(default)s)')
    d.add_argument('--data', default=str(DEFAULT_DATA), help='shared data directory (default %(default)s)')
    s = add('stability', cmd_stability, 'Routh-Hurwitz thresholds in delta and critical delays tau_c')
    s.add_argument('--config', default=str(DEFAULT_CONFIG), help='paper parameter YAML (default %(default)s)')
    m = add('demo', cmd_demo, 'the main job on the default configuration: design and stability report')
    m.add_argument('--config', default=str(DEFAULT_CONFIG), help='paper parameter YAML (default %(default)s)')
    m.add_argument('--data', default=str(DEFAULT_DATA), help='shared data directory (default %(default)s)')
    r = add('run', cmd_run, 'closed-loop run of the ROS 2 nodes (simulator, controller, recorder) in a fresh '
            'ROS domain on loopback, recorded to a rosbag2 MCAP directory')
    r.add_argument('--config', default=str(Path(DEFAULT_CONFIG).parent / 'default.yaml'),
                   help='scenario parameter file (sim_node / controller_node sections; default %(default)s)')
    r.add_argument('--duration', type=float, default=None,
                   help='simulated seconds (default: the file\'s sim_node duration; 0 = until Ctrl-C)')
    r.add_argument('--out', required=True, help='output directory: bag/, scenario.yaml, logs/, summary.json')
    r.add_argument('--domain', type=int, default=None, help='ROS_DOMAIN_ID (default: a free one in 1..232)')
    r.add_argument('--timeout', type=float, default=None, help='stop the run after this many wall seconds')
    a = add('analyze', cmd_analyze, 'classify recorded runs (settled, limit cycle, growing, fallen): amplitude, '
            'period, sticking, plots; reads rosbag2 directories, run directories or .mcap files without ROS')
    a.add_argument('runs', nargs='+', help='run directory, rosbag2 directory or .mcap file')
    a.add_argument('--plots', default='runs/analysis', help='directory for PNG figures (default %(default)s)')
    a.add_argument('--no-plots', action='store_true', help='numbers only')
    w = add('sweep', cmd_sweep, 'stability map over the delay tau and the initial angle theta0 (Figures 11-12), '
            'offline physics core, parallel and resumable')
    w.add_argument('--config', default=str(REPO_ROOT / 'config' / 'fig9_new_gain_exponential.yaml'), help='base scenario (default %(default)s)')
    w.add_argument('--tau', default='0:0.14:0.005', help='delays [s], start:stop:step or a,b,c (default %(default)s)')
    w.add_argument('--theta0-deg', default='0:12:0.5', help='initial angles [deg] (default %(default)s)')
    w.add_argument('--duration', type=float, default=20.0, help='simulated seconds per cell (default %(default)s)')
    w.add_argument('--sensors', choices=('exact', 'config'), default='exact',
                   help='exact states as in the paper\'s simulations, or the scenario\'s encoders (default %(default)s)')
    w.add_argument('--smoothing', choices=('none', 'tanh'), default=None, help='override the friction smoothing')
    w.add_argument('--workers', type=int, default=None, help='processes (default: all cores)')
    w.add_argument('--out', required=True, help='directory for cells.csv, map.png, summary.json')
    b = add('bench', cmd_bench, 'benchmarks beside their references (scipy, MuJoCo, raw rclpy): offline closed '
            'loop, Figure-11 sweep, ROS lockstep and realtime loops, analyze, identify; table and bench/RESULTS.md')
    b.add_argument('--quick', action='store_true', help='tiny sizes: check that every benchmark runs (no targets)')
    b.add_argument('--realtime-duration', type=float, default=600.0,
                   help='seconds of the realtime ROS run whose bag analyze reads (default %(default)s)')
    b.add_argument('--results', default=None, help='where to write the table (default bench/RESULTS.md, '
                   'runs/bench-quick/RESULTS.md with --quick)')
    return p


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except ConfigError as exc:
        print(f'ipfric {args.command}: configuration error: {exc}', file=sys.stderr)
        return 2


if __name__ == '__main__':
    sys.exit(main())
