"""Command line of ipfric: ``./ipfric <command> [--json]``."""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from .design.paperconfig import DEFAULT_CONFIG, DEFAULT_DATA, REPO_ROOT, load_paper_config
from .executor import SchedulerError
from .ident.records import ANGLE_ZEROS
from .physics.params import ConfigError


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


def _check_case(scn, label: str, value: float):
    """The design check's view of scenario ``scn``: its physics and its loops (design.check.LOOPS)."""
    from dataclasses import replace

    from .design.check import CheckCase
    viscous = replace(scn, friction=scn.friction.replace(model='viscous', smoothing='none'))
    c = scn.controller
    rigs = {'exact': _exact_sensors(scn), 'encoders': scn, 'viscous': _exact_sensors(viscous), 'floor': viscous}
    return CheckCase(label, value, scn.plant, scn.friction, tuple(scn.gain()), c.delay, c.cutoff_hz,
                     {k: v.make_rig().loop_spec() for k, v in rigs.items()}, scn.make_controller().loop_spec())


def _design_check(args) -> int:
    """``./ipfric design --check``: the page of a gain on a scenario (Markdown, PNG, JSON in --out)."""
    config = args.config or str(REPO_ROOT / 'config' / 'default.yaml')
    if args.from_ident and args.friction_change is not None:
        raise ConfigError('--friction-change with --from-ident: the identification\'s standard errors set the '
                          'friction cases; give one of them')
    change = 0.3 if args.friction_change is None else args.friction_change
    if not (math.isfinite(change) and 0.0 < change < 1.0):
        raise ConfigError(f'--friction-change: {change!r} must be in (0, 1) (0.3 = friction x0.7 and x1.3)')
    if not (math.isfinite(args.max_delay) and 0.0 < args.max_delay <= 1.0):
        raise ConfigError(f'--max-delay: {args.max_delay!r} s must be in (0, 1] s')
    from .run.scenario import load_scenario
    try:
        base = load_scenario(config)
    except ConfigError as exc:
        raise ConfigError(f'--config: {exc} (with --check: a scenario, e.g. config/default.yaml)') from None
    if args.max_delay <= base.controller.delay:
        raise ConfigError(f'--max-delay: {args.max_delay:g} s must exceed the scenario\'s delay '
                          f'({base.controller.delay:g} s)')
    if args.from_ident:
        from .ident.uncertainty import friction_shift, load_report
        model, std, dt = load_report(args.from_ident)
        scenarios = [(f'friction {k:+d} SE' if k else 'identified', k, friction_shift(model, std, dt, base, k)[1])
                     for k in (-1, 0, 1)]
        axis = f'friction coefficients [standard errors of {args.from_ident}]'
    else:
        from .analysis.sweep import scenario_at
        lo, hi = 1.0 - change, 1.0 + change
        scenarios = [(f'friction x{lo:g}', lo, scenario_at(base, 'friction', lo)), ('scenario', 1.0, base),
                     (f'friction x{hi:g}', hi, scenario_at(base, 'friction', hi))]
        axis = 'friction scale (mu_s, mu_c, eps)'
    cases = [_check_case(scn, label, value) for label, value, scn in scenarios]
    import time

    from .analysis.plots import check_figure
    from .design.check import design_check
    from .design.reports import check_page
    t0 = time.perf_counter()

    def progress(msg):
        print(f'[design --check] {time.perf_counter() - t0:5.1f} s  {msg}', file=sys.stderr)
    res = design_check(cases[1], [cases[0], cases[2]], args.max_delay, None if args.json else progress)
    res.update(config=config, scenario=Path(config).stem, axis=axis, from_ident=args.from_ident,
               encoders={'cart_m': base.sim.cart_resolution, 'angle_rad': base.sim.angle_resolution},
               sample_period_s=base.sample_period, seconds=round(time.perf_counter() - t0, 1))
    out = Path(args.out or 'runs/design-check')
    out.mkdir(parents=True, exist_ok=True)
    res['files'] = {'page': str(out / 'check.md'), 'figure': str(out / 'check.png'), 'json': str(out / 'check.json')}
    check_figure(res, out / 'check.png')
    (out / 'check.md').write_text(check_page(res, 'check.png'))
    (out / 'check.json').write_text(json.dumps(res, indent=2, default=float))
    if args.json:
        _print_json(res)
        return 0
    print(res['verdict'])
    print(f'page: {out / "check.md"}\nfigure: {out / "check.png"}\nnumbers: {out / "check.json"} '
          f'({res["seconds"]} s)')
    return 0


def cmd_design(args) -> int:
    if args.check:
        return _design_check(args)
    extra = [o for o, v in (('--out', args.out), ('--from-ident', args.from_ident),
                            ('--friction-change', args.friction_change)) if v is not None]
    if extra:
        raise ConfigError(f'{", ".join(extra)}: only with --check')
    cfg = load_paper_config(args.config or DEFAULT_CONFIG)      # bad input refused before the long imports
    from .design.reports import design_report
    tables = Path(args.data) / 'paper'
    if not tables.is_dir():
        print(f'[design] {tables} is absent: the friction estimates of the appendix tables are left out (--data)',
              file=sys.stderr)
    rep = design_report(cfg, tables if tables.is_dir() else None)
    if args.json:
        _print_json(rep)
        return 0
    print(f'LQR gains, V = +K x, Q = diag{cfg.Q}, R = {cfg.R:g}  ({args.config or DEFAULT_CONFIG})')
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
    if 'friction_estimates' not in rep:
        return 0
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
    cfg = load_paper_config(args.config)
    from .design.reports import stability_report
    rep = stability_report(cfg)
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
    """The README's main job: a closed-loop ROS 2 run of the default scenario, then its analysis."""
    import time

    from .analysis.recorded_run import analyze_run
    from .run.runner import Run
    out = Path(args.out) if args.out else REPO_ROOT / 'runs' / time.strftime('demo-%Y%m%d-%H%M%S')
    r = Run(args.config, out, args.duration, timeout=600.0)
    if not args.json:
        print(f'[demo] closed-loop run of {args.config} through the ROS 2 nodes -> {out}', file=sys.stderr)
    r.start()
    try:
        res = r.wait()
    except KeyboardInterrupt:
        r.kill()
        raise
    if res.exit_code != 0:
        print(res.summary(), file=sys.stderr)
        return res.exit_code
    a = analyze_run(out, out / 'plots')
    summary = {'run': res.to_dict(), 'analysis': a}
    (out / 'analysis.json').write_text(json.dumps(summary, indent=2, default=float))
    if args.json:
        _print_json(summary)
        return 0
    print(res.summary())
    print()
    _print_analysis(a)
    print(f'analysis: {out / "analysis.json"}')
    return 0


def cmd_run(args) -> int:
    from .run.runner import cmd_run as run
    return run(args)


def _print_analysis(r: dict) -> None:
    """Readable summary of one :func:`analysis.analyze_run` result."""
    print(f'{r["path"]}: {r["class"]}' + (' (TRUNCATED: ' + r['truncation_detail'] + ')' if r['truncated'] else ''))
    for d in r.get('damage', ()):
        print(f'  DAMAGED: {d}')
    if r.get('class') is None:
        return
    tt = r['transition_time']
    print(f'  {r["samples"]} samples, {r["duration_s"]:.2f} s, end: {r["end_reason"]}; '
          + ('still converging' if tt is None else f'final regime from t = {tt:.3f} s'))
    print(f'  p2p: cart {r["x_p2p"] * 100:.3f} cm, angle {math.degrees(r["theta_p2p"]):.4f} deg; '
          f'cart at rest {100 * r["stick_fraction"]:.0f} % of the window')
    if r['period_crossings'] or r['period_spectrum']:
        pc, ps = r['period_crossings'], r['period_spectrum']
        print(f'  period: {pc and round(pc, 3)} s (zero crossings), {ps and round(ps, 3)} s (spectrum)'
              + ('' if r['periods_agree'] else ': estimates disagree, an irregular oscillation')
              + (f'; {r["frequency"]:.3f} Hz' if r['frequency'] else ''))
    if r.get('samples_without_command') is not None:
        lat = r.get('command_latency_s') or {}
        print(f'  {r["time_mode"]}: {r["samples_without_command"]} samples without a fresh command '
              f'({100 * r["samples_without_command"] / r["samples"]:.2f} %)'
              + (f'; command latency median {lat["median"] * 1e3:.3f} ms, p99 {lat["p99"] * 1e3:.3f} ms, '
                 f'max {lat["max"] * 1e3:.3f} ms' if lat.get('median') is not None else ''))
    if 'figure' in r:
        print(f'  figure: {r["figure"]}')


def _column_map(text: str | None) -> dict:
    """--columns t=time_s,x=cart_m,... as name -> CSV header."""
    columns = {}
    for item in text.split(',') if text else []:
        key, _, name = item.partition('=')
        if not name:
            raise ConfigError(f'--columns: {item!r} is not NAME=HEADER (names t, x, voltage, theta)')
        columns[key.strip()] = name.strip()
    return columns


LOG_SUFFIXES = ('.csv', '.mat')


def _print_log_analysis(r: dict) -> None:
    """Readable summary of one :func:`analysis.analyze_log` result: a row per regime."""
    print(f'{r["path"]}: {r["samples"]} samples, {r["duration_s"]:.2f} s every {r["sample_period_s"] * 1e3:.3g} ms, '
          f'angle from {r["angle_zero"]}; {len(r["segments"])} balanced stretch(es)')
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


def cmd_analyze(args) -> int:
    """Exit code 0: every bag intact; 1: a bag truncated or damaged (what was read is analysed,
    the loss stated); 2: an input refused (not an MCAP file, no bag)."""
    from .analysis.recorded_run import analyze_log, analyze_run, overlay_runs
    plots = None if args.no_plots else args.plots
    logs = [p for p in args.runs if Path(p).suffix.lower() in LOG_SUFFIXES]
    if logs and len(logs) != len(args.runs):
        raise ConfigError('give either rig logs (.csv, .mat) or runs (bags), not both')
    if logs:
        columns = _column_map(args.columns)
        results = [analyze_log(p, columns, args.angle_zero, math.radians(args.max_angle_deg),
                               args.min_balanced_s, plots) for p in logs]
        if args.json:
            _print_json({'logs': results})
        for r in [] if args.json else results:
            _print_log_analysis(r)
        return 0
    results = [analyze_run(p, plots) for p in args.runs]
    out: dict = {'runs': results}
    if len(args.runs) > 1 and not args.no_plots:
        out['overlay'] = overlay_runs(args.runs, Path(args.plots) / 'overlay.png')
    code = 1 if any(r['truncated'] or r['damage'] for r in results) else 0
    if args.json:
        _print_json(out)
        return code
    for r in results:
        _print_analysis(r)
    if 'overlay' in out:
        print(f'overlay: {out["overlay"]["figure"]}')
    return code


def _exact_sensors(scn):
    """Scenario ``scn`` with exact states for encoders (counts of 0)."""
    from dataclasses import replace
    return replace(scn, sim=replace(scn.sim, cart_resolution=0.0, angle_resolution=0.0))


def _sweep_base(config, sensors, smoothing, cutoff_hz=None):
    from dataclasses import replace

    from .run.scenario import load_scenario
    base = load_scenario(config)
    if cutoff_hz is not None:
        if not (math.isfinite(cutoff_hz) and cutoff_hz >= 0):
            raise ConfigError(f'--cutoff-hz: {cutoff_hz!r} must be >= 0 Hz (0 = raw difference)')
        base = replace(base, controller=replace(base.controller, cutoff_hz=cutoff_hz))
    if sensors == 'exact':
        base = _exact_sensors(base)
    if smoothing:
        base = replace(base, friction=base.friction.replace(smoothing=smoothing))
    return base


# The paper's Figures 11-12: scenario, variants (label, smoothing, line style), grids (name, theta0 range [deg])
FIGURES: dict[str, tuple[str, list[tuple[str, str | None, str]]]] = {
    '11': ('fig9_new_gain_exponential.yaml', [('sgn', 'none', '--'), ('tanh(100v)', 'tanh', '-')]),
    '12': ('fig10_new_gain_dynamic.yaml', [('dynamic', None, '-')]),
}
# theta0 = 0 is left out: with exact sensors the run stays at the equilibrium for any delay
FIGURE_GRIDS = (('full', '0.5:12:0.5'), ('zoom', '0.025:0.5:0.025'))


def _figure_sweep(args, taus, progress) -> dict:
    from .analysis.plots import transition_figure
    from .analysis.sweep import boundaries, grid, parse_range, sweep
    name, variants = FIGURES[args.figure]
    config = REPO_ROOT / 'config' / name
    out = Path(args.out)
    panels, result = [], {'figure_of_paper': args.figure, 'config': str(config), 'variants': {}}
    for gname, trange in FIGURE_GRIDS:
        ths = parse_range(trange)
        panel: dict = {'title': f'θ0 {ths[0]:g}-{ths[-1]:g} deg', 'taus': taus, 'thetas_deg': ths, 'curves': []}
        for label, smoothing, style in variants:
            base = _sweep_base(config, args.sensors, smoothing, args.cutoff_hz)
            d = out / f'{gname}_{smoothing or "model"}'
            if progress:
                print(f'[sweep] {label}, {gname} grid -> {d}', file=sys.stderr)
            rows = sweep(base, taus, ths, args.duration, d, args.workers, progress, ros=args.ros,
                         scheduler=args.scheduler)
            b = boundaries(rows, taus, ths)
            panel.setdefault('classes', grid(rows, taus, ths))
            panel['curves'].append((label, style, ths, [r['first_unsettled_tau_s'] for r in b],
                                    [r['first_fallen_tau_s'] for r in b]))
            result['variants'].setdefault(label, {})[gname] = {'csv': str(d / 'cells.csv'), 'boundaries': b}
        panels.append(panel)
    title = f'Figure {args.figure}: {name.removesuffix(".yaml")}, {args.sensors} sensors, {args.duration:g} s runs'
    result['figure'] = str(transition_figure(panels, title, out / f'figure{args.figure}.png'))
    return result


def _resolution_sweep(args, out: Path) -> int:
    from .analysis.plots import resolution_figure
    from .analysis.sweep import parse_range, resolution_study
    try:
        scales = parse_range(args.resolution_scale)
    except ValueError as exc:
        raise ConfigError(f'--resolution-scale: {exc}') from exc
    if (scales < 0).any():
        raise ConfigError('--resolution-scale: scales must be >= 0 (0 = exact sensors, 1 = the scenario\'s)')
    base = _sweep_base(args.config, 'config', args.smoothing, args.cutoff_hz)
    rows = resolution_study(base, scales, args.duration, args.scale_sensor, args.workers, args.scheduler)
    out.mkdir(parents=True, exist_ok=True)
    fig = resolution_figure(rows, f'{Path(args.config).stem}: oscillation against {args.scale_sensor} '
                            'encoder resolution',
                            out / 'resolution.png')
    summary = {'config': args.config, 'duration_s': args.duration, 'scaled': args.scale_sensor, 'rows': rows,
               'figure': str(fig)}
    (out / 'resolution.json').write_text(json.dumps(summary, indent=2, default=float))
    if args.json:
        _print_json(summary)
        return 0
    print(f'{"scale":>6} {"angle count":>12} {"class":>12} {"cart p2p":>10} {"angle p2p":>10}')
    for r in rows:
        print(f'{r["scale"]:6.2f} {math.degrees(r["angle_resolution_rad"]):10.5f}° {r["class"]:>12} '
              f'{r["true_x_p2p_m"] * 1e3:8.3f}mm {math.degrees(r["true_theta_p2p_rad"]):9.4f}°')
    print(f'figure: {fig}')
    return 0


def _threshold(args, out: Path) -> int:
    from .analysis.sweep import threshold_angle
    try:
        lo, hi = (float(v) for v in args.threshold.split(','))
    except ValueError as exc:
        raise ConfigError(f'--threshold: {args.threshold!r}: expected LO,HI in rad, e.g. 1e-5,1e-3') from exc
    if not 0 <= lo < hi:
        raise ConfigError(f'--threshold: need 0 <= LO < HI, got {lo:g}, {hi:g}')
    base = _sweep_base(args.config, args.sensors, args.smoothing, args.cutoff_hz)

    def progress(a, b):
        print(f'[threshold] settles from {a:.4g} rad, cycles from {b:.4g} rad', file=sys.stderr)
    try:
        res = threshold_angle(base, lo, hi, args.duration, progress=None if args.json else progress,
                              scheduler=args.scheduler)
    except ValueError as exc:
        raise ConfigError(f'--threshold: {exc}') from exc
    res.update(config=args.config, sensors=args.sensors, cutoff_hz=base.controller.cutoff_hz,
               duration_s=args.duration)
    out.mkdir(parents=True, exist_ok=True)
    (out / 'threshold.json').write_text(json.dumps(res, indent=2, default=float))
    if args.json:
        _print_json(res)
        return 0
    print(f'converges for theta0 <= {res["settles_below_rad"]:.4g} rad, leaves the equilibrium from '
          f'{res["oscillates_from_rad"]:.4g} rad ({res["runs"]} runs of {args.duration:g} s); that run ends '
          f'{res["hi_class"].replace("_", " ")}, cart p2p {res["hi_x_p2p_m"] * 1e3:.2f} mm over the last 20 s')
    return 0


def cmd_sweep(args) -> int:
    from .analysis.oscillation import CLASSES
    from .analysis.plots import stability_map
    from .analysis.sweep import boundaries, grid, parse_range, print_progress, sweep
    try:
        taus, ths = parse_range(args.tau), parse_range(args.theta0_deg)
    except ValueError as exc:
        raise ConfigError(f'--tau/--theta0-deg: {exc}') from exc
    progress = None if args.json else print_progress
    out = Path(args.out)
    if args.ros and args.scheduler:
        raise ConfigError('--ros with --scheduler: a ROS cell runs three node processes on this machine; '
                          'drop one of them')
    if args.figure:
        summary = _figure_sweep(args, taus, progress)
        (out / 'summary.json').write_text(json.dumps(summary, indent=2, default=float))
        if args.json:
            _print_json(summary)
            return 0
        for label, grids in summary['variants'].items():
            for gname, g in grids.items():
                print(f'{label}, {gname}:')
                for b in g['boundaries']:
                    print(f'  theta0 {b["theta0_deg"]:6.3f} deg: settled up to tau = {b["last_settled_tau_s"]}, '
                          f'falls from tau = {b["first_fallen_tau_s"]}')
        print(f'figure: {summary["figure"]}')
        return 0
    if args.resolution_scale:
        return _resolution_sweep(args, out)
    if args.threshold:
        return _threshold(args, out)
    base = _sweep_base(args.config, args.sensors, args.smoothing, args.cutoff_hz)
    rows = sweep(base, taus, ths, args.duration, out, args.workers, progress, ros=args.ros,
                 scheduler=args.scheduler)
    title = f'{Path(args.config).stem}: {base.friction.model}' + (
        f', tanh({base.friction.delta:g} v)' if base.friction.smoothing == 'tanh' else '')
    fig = stability_map(taus, ths, grid(rows, taus, ths), title, out / 'map.png')
    summary = {'config': args.config, 'sensors': args.sensors, 'duration_s': args.duration,
               'path': 'ros lockstep' if args.ros else 'offline',
               'cells': len(rows), 'figure': str(fig), 'csv': str(out / 'cells.csv'),
               'counts': {c: sum(r['class'] == c for r in rows) for c in CLASSES},
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


def cmd_montecarlo(args) -> int:
    """The hunting's distribution over N runs with parameters drawn from --spread or --from-ident."""
    from functools import partial
    if args.runs < 1:
        raise ConfigError(f'--runs: {args.runs} must be >= 1')
    if not (math.isfinite(args.duration) and args.duration > 0):
        raise ConfigError(f'--duration: {args.duration!r} must be > 0 s')
    if (args.spread is None) == (args.from_ident is None):
        raise ConfigError('give either --spread NAME=S,... (relative spreads) or --from-ident DIR (an '
                          'identification\'s parameter table)')
    if args.workers is not None and args.workers < 1:
        raise ConfigError(f'--workers: {args.workers} must be >= 1')
    base = _sweep_base(args.config, args.sensors, None)
    from .analysis.montecarlo import parse_spread, run_montecarlo, spread_draw, write_results
    from .analysis.sweep import print_progress
    info: dict = {'config': args.config, 'runs': args.runs, 'duration_s': args.duration, 'seed': args.seed,
                  'sensors': args.sensors}
    if args.spread is not None:
        spread = parse_spread(args.spread)
        draw = partial(spread_draw, base, spread, args.seed, distribution=args.distribution)
        info['drawn'] = {'spread': spread, 'distribution': args.distribution,
                         'meaning': 'value = nominal * (1 + s z), z ~ N(0, 1)' if args.distribution == 'normal'
                         else 'value = nominal * (1 + s u), u ~ U(-1, 1)'}
    else:
        from .ident.uncertainty import load_report, report_draw
        model, std, dt = load_report(args.from_ident)
        draw = partial(report_draw, model, std, dt, base, args.seed)
        info['drawn'] = {'from_ident': args.from_ident, 'std': std,
                         'meaning': 'value ~ N(identified value, std^2), independent, clipped to the bounds'}
    rows = run_montecarlo(draw, args.runs, args.duration, args.workers, args.scheduler,
                      None if args.json else partial(print_progress, label='runs'))
    title = f'{Path(args.config).stem}: {args.runs} runs of {args.duration:g} s, ' + (
        f'spread {args.spread} ({args.distribution})' if args.spread else f'from {args.from_ident}')
    summary = write_results(rows, info, args.out, title)
    if args.json:
        _print_json(summary)
        return 0
    print(f'{args.runs} runs: ' + ', '.join(f'{c} {100 * f:.1f} %' for c, f in summary['fraction'].items() if f))
    for key, label, scale, unit in (('true_x_p2p_m', 'cart p2p', 100.0, 'cm'),
                                    ('true_theta_p2p_rad', 'angle p2p', 180.0 / math.pi, 'deg'),
                                    ('period_s', 'period', 1.0, 's')):
        q = summary[key]
        if q:
            print(f'  {label:<10} 5/25/50/75/95 %: ' + ' / '.join(f'{scale * q[k]:.3g}' for k in
                                                                  ('q05', 'q25', 'q50', 'q75', 'q95'))
                  + f' {unit} ({q["runs"]} hunting runs)')
    print(f'summary: {Path(args.out) / "summary.json"}\nruns: {summary["csv"]}\nfigure: {summary["figure"]}')
    return 0


def cmd_identify(args) -> int:
    """Identification on measured data, the paper tables, or the closed-loop redesign."""
    from .ident.effects import EFFECTS
    if args.loop:
        from .ident.redesign import close_the_loop
        out = close_the_loop(args.loop, args.out, args.duration, args.base, not args.no_plots)
        if args.json:
            _print_json(out)
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
    from .physics.params import PlantParams, load_yaml
    plant = None  # a bag then uses the plant of its stored scenario, the rest Table 1
    if args.plant and 'sim_node' in load_yaml(args.plant):
        from .run.scenario import load_scenario
        plant = load_scenario(args.plant).plant
    elif args.plant:
        data = load_yaml(args.plant)
        if 'plant' not in data:
            raise ConfigError(f'{args.plant}: no plant: section (a scenario has sim_node:, a plant file plant:)')
        plant = PlantParams.from_dict(data['plant'], f'{args.plant}: plant')
    if args.data == 'paper':
        from .design.estimation import load_table5, load_table6
        from .ident.equation_error import identify_steady
        d = Path(args.tables)
        V, v, _, _, aside = load_table5(d / 'table5_constant_voltage.csv')
        rep = identify_steady(plant or PlantParams(), V, v, load_table6(d / 'table6_breakaway_voltage.csv'))
        rep['runs_set_aside'] = [{'voltage_V': a, 'value_mps': b, 'row_average_mps': c} for a, b, c in aside]
        if args.json:
            _print_json(rep)
            return 0
        print('Tables 5 and 6 through the force balance (coulomb effect, F_N = M g):')
        for k in ('mu_c', 'eps', 'mu_s'):
            print(f'  {k:<5} {rep[k]:.5f} +/- {rep[k + "_std"]:.5f}')
        print(f'  sliding residual RMS {rep["sliding_rms_N"]:.4f} N, breakaway residual RMS '
              f'{rep["breakaway_rms_N"]:.4f} N, curvature of the residual over the velocity range '
              f'{rep["residual_curvature_N"]:+.4f} N')
        return 0
    from .ident.records import load
    columns = _column_map(args.columns)
    rec = load(args.data, plant, columns, args.cart_alone)
    allowed = None
    if args.effects:
        allowed = [e.strip() for e in args.effects.split(',')]
        bad = [e for e in allowed if e not in EFFECTS]
        if bad:
            raise ConfigError(f'--effects: unknown effect(s) {", ".join(bad)}; allowed: {", ".join(EFFECTS)}')
    if args.validation:
        est, val = rec, load(args.validation, plant, columns, args.cart_alone)
    else:
        if not 0.2 <= args.split <= 0.9:
            raise ConfigError(f'--split: {args.split:g} is out of range; allowed [0.2, 0.9]')
        est, val = rec.split(args.split)
    if Path(args.data).suffix.lower() == '.mat':
        return _identify_force_input(args, est, val, allowed)
    from .ident.ladder import run_ladder
    from .ident.ladder_report import write_ladder_report
    from .ident.model import load_declared
    model = load_declared(args.plant, args.base, rec.theta is not None, plant)
    if args.free:
        model = model.freeing([n.strip() for n in args.free.split(',')])
    say = None if args.json else (lambda msg: print(msg, file=sys.stderr))
    r = write_ladder_report(run_ladder(est, val, model, allowed, say), args.out, not args.no_plots)
    if args.export:
        from .ident.redesign import export_scenario
        from .run.scenario import load_scenario
        idf = r['identified']
        r['export'] = export_scenario(args.export, r['ladder'][-1]['step'], idf, load_scenario(args.scenario),
                                      load_scenario(args.rig) if args.rig else None)
    if args.json:
        _print_json(r)
        return 0
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
    print('  ' + ', '.join(f'{p["name"]} {_fmt_param(p)}' for p in last['params'] if p['fitted']))
    from .ident.ladder_report import correlation_lines
    for line in correlation_lines(last, {p['name']: p['unit'] for p in last['params']}):
        print(f'  {line}')
    rough = [p['name'] for p in last['params'] if p.get('rough')]
    if rough:
        print(f'  the simulated error is rough in {", ".join(rough)}: their errors come from a scan of the error '
              f'along each')
    print(f'  report {Path(args.out) / "report.md"}')
    if args.export:
        print(f'  exported {r["export"]["scenario"]}' + (f' and {r["export"]["on_rig"]}' if args.rig else ''))
    return 0


def _fmt_param(p: dict) -> str:
    std = f' +/- {p["std"]:.2g}' if p['std'] is not None and math.isfinite(p['std']) else ''
    return f'{p["value"]:.4g}{std} {p["unit"]}'.rstrip()


def _identify_force_input(args, est, val, allowed) -> int:
    """A force-input record without a declared plant (EMPS): the equation-error search, with the
    simulation error of its result beside the force error."""
    from .ident.equation_error import identify
    from .ident.report import write_report
    r = write_report(identify(est, val, args.base, allowed), args.out, not args.no_plots)
    if args.json:
        _print_json(r)
        return 0
    print(f'{r["data"]["estimation"]} / {r["data"]["validation"]}: base {r["base_model"]}, effects added: '
          f'{", ".join(r["effects_added"]) or "none"}')
    for tag in ('error_before', 'error_after'):
        e = r[tag]
        print(f'  {tag.replace("_", " "):<13} estimation {e["estimation"]["relative_percent"]:.3f} % '
              f'(RMS {e["estimation"]["rms"]:.4g} N), validation {e["validation"]["relative_percent"]:.3f} % '
              f'(RMS {e["validation"]["rms"]:.4g} N)')
    sim = r['simulation_error']
    print(f'  simulation error (validation): {sim["x_rms_counts"]:.3g} counts, {sim["x_percent"]:.3g} % of the motion')
    for t in r['effects_tried']:
        print(f'  tried {t["name"]:<11} validation gain {t["validation_gain_percent"]:7.2f} %  '
              f'p {t["validation_p"]:.2g}  {"kept" if t["kept"] else "rejected"}')
    print('  ' + ', '.join(f'{k} {p["value"]:.5g} +/- {p["std"]:.2g} {p["unit"]}' for k, p in r['params'].items()))
    print(f'  report {Path(args.out) / "report.md"}')
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


def _orbit_loop(base, name: str, value: float, delay: float | None = None):
    """The sampled loop of scenario ``base`` at parameter ``name`` = ``value`` (a continuation
    parameter or theta0 [rad]), with the feedback delay ``delay`` [s] (default the scenario's)
    unless the parameter is the delay; a delay may fall between samples here."""
    from dataclasses import replace

    from .analysis.sweep import scenario_at
    from .design.orbit import loop_numbers
    if name == 'theta0':
        scn = replace(base, sim=replace(base.sim, theta0=value))
    else:
        scn = base if name == 'delay' else scenario_at(base, name, value)
    return loop_numbers(scn.make_rig().loop_spec(), scn.make_controller().loop_spec(),
                        value if name == 'delay' else base.controller.delay if delay is None else delay)


def _basin(args, base, delay: float):
    """--basin LO,HI: the edge of the upright's basin over theta0 and the orbit on it (summary, Edge)."""
    from .design.basin import basin_edge, shape_threshold
    try:
        lo, hi = (float(v) for v in args.basin.split(','))
    except ValueError:
        raise ConfigError(f'--basin: {args.basin!r}: expected LO,HI in rad, e.g. 1e-4,0.05') from None
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 <= lo < hi):
        raise ConfigError(f'--basin: need finite 0 <= LO < HI [rad], got {args.basin!r}')
    if not (math.isfinite(args.duration) and args.duration > 0):
        raise ConfigError(f'--duration: {args.duration!r} must be a positive number of seconds')

    def loop_at(theta0):
        return _orbit_loop(base, 'theta0', theta0, delay)
    try:
        edge = basin_edge(loop_at, lo, hi, duration=args.duration)
    except ValueError as exc:
        raise ConfigError(f'--basin: {exc}') from None
    out = edge.summary()
    if edge.orbit is not None:
        out['shape_threshold'] = list(shape_threshold(loop_at(edge.settles_below), edge.orbit,
                                                      duration=args.duration))
    return out, edge


def cmd_orbit(args) -> int:
    base = _sweep_base(args.config, args.sensors, args.smoothing, args.cutoff_hz)
    from .design.continuation import parse_continuation
    cont = None
    if args.continue_:
        try:
            cont = parse_continuation(args.continue_)
        except ValueError as exc:
            raise ConfigError(str(exc)) from None
        from .analysis.sweep import PARAMETERS
        if cont[0] not in PARAMETERS:
            raise ConfigError(f'--continue {cont[0]!r}: unknown parameter; allowed: {", ".join(PARAMETERS)} '
                              '(delay [s]; gain and friction as multiples of the scenario\'s)')
        if cont[0] == 'delay' and min(cont[1:3]) < 0:
            raise ConfigError('--continue delay: delays must be >= 0 s')
    delay = base.controller.delay
    if args.delay is not None:
        if not (math.isfinite(args.delay) and args.delay >= 0):
            raise ConfigError(f'--delay: {args.delay!r} must be finite and >= 0 s')
        from .analysis.sweep import scenario_at
        delay, base = args.delay, scenario_at(base, 'delay', args.delay)   # runs: whole samples
    import time

    from .design.continuation import trace, unstable_partners
    from .design.orbit import OrbitError, find_orbit
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    loop = _orbit_loop(base, 'delay', delay, delay)
    try:
        main_orbit = find_orbit(loop)
        orbits = [main_orbit] + unstable_partners(loop, main_orbit)
    except OrbitError as exc:
        orbits, why = [], str(exc)
    took = time.perf_counter() - t0
    res: dict = {'config': args.config, 'sensors': args.sensors, 'delay_s': delay,
                 'orbits': [o.summary() for o in orbits], 'seconds': round(took, 3)}
    if not orbits:
        res['no_orbit'] = why
    edge = None
    if args.basin:
        res['basin'], edge = _basin(args, base, delay)
    if args.simulate > 0:
        from .design.orbit import simulated_cycle
        res['simulation'] = simulated_cycle(base.make_rig(), base.make_controller(), args.simulate)
        res['simulation']['delay_s'] = base.controller.delay
    if cont:
        name, start, stop, count = cont

        def progress(text):
            print(f'[orbit] {name}: {text} ({time.perf_counter() - t0:.1f} s)', file=sys.stderr, flush=True)

        t0 = time.perf_counter()
        from contextlib import nullcontext

        from .executor import make_executor
        with make_executor(args.scheduler) if args.scheduler else nullcontext() as cluster:
            given = [(delay if name == 'delay' else 1.0, edge.orbit)] if edge and edge.orbit else []
            found = trace(lambda v: _orbit_loop(base, name, v, delay), start, stop, count,
                          progress=None if args.json else progress, executor=cluster, orbits=given)
        events = found.events
        res['continuation'] = {'parameter': name, 'range': [start, stop], 'points': len(found.points),
                               'branches': len({p.branch for p in found.points}), 'events': events,
                               'probes': found.probes, 'jacobians': found.jacobians, 'steps': found.steps,
                               'seconds': round(time.perf_counter() - t0, 2)}
        values = [start + (stop - start) * i / 28 for i in range(29)]   # the simulations beside the branches
        import csv
        rows = [p.row() for p in found.points]
        with open(out / 'branches.csv', 'w', newline='') as fh:
            wr = csv.DictWriter(fh, fieldnames=list(rows[0]) if rows else ['parameter'])
            wr.writeheader()
            wr.writerows(rows)
        if not args.no_plots:
            from .analysis.bifurcation import diagram
            df = None
            if args.describing and name in ('delay', 'gain'):
                from .design.describing import hunting_over_delays, hunting_over_gain_scales
                c = base.controller
                df = (hunting_over_delays(base.plant, base.friction, base.gain(), values, c.cutoff_hz)
                      if name == 'delay' else
                      hunting_over_gain_scales(base.plant, base.friction, base.gain(), values, c.delay, c.cutoff_hz))
                df = [{'parameter': v, 'x_p2p_m': d['x_p2p_m']} for v, d in zip(values, df) if d['intersection']]
                res['continuation']['describing_function'] = df
            res['continuation']['plot'] = str(diagram(base, name, values, rows, events, out / 'bifurcation.png', df))
    (out / 'orbit.json').write_text(json.dumps(res, indent=2, default=float))
    if args.json:
        _print_json(res)
        return 0
    print(f'Periodic orbits of {args.config} ({args.sensors} sensors, delay {delay:g} s), {took:.2f} s')
    if not orbits:
        print(f'  none: {why}')
    for o in orbits:
        m = o.largest_multiplier
        print(f'  {"stable  " if o.stable else "unstable"} x p2p {100 * o.x_p2p:.4f} cm, theta p2p '
              f'{o.theta_p2p:.3e} rad, period {o.period:.5f} s, stuck {100 * o.stuck_fraction:.1f} % '
              f'({o.sticks} sticking phases), largest multiplier |{m:.3g}|')
    if 'basin' in res:
        b = res['basin']
        print(f'  basin of the upright: runs from theta0 <= {b["settles_below_rad"]:.6g} rad settle, from '
              f'{b["leaves_from_rad"]:.6g} rad they leave ({b["runs"]} runs of up to {args.duration:g} s)')
        if b['orbit']:
            o = b['orbit']
            f_lo, f_hi = b['shape_threshold']
            print(f'    the run at the edge lingers on the unstable orbit x p2p {100 * o["x_p2p_m"]:.4f} cm, theta '
                  f'p2p {o["theta_p2p_rad"]:.4e} rad, period {o["period_s"]:.5f} s, largest multiplier '
                  f'|{o["max_multiplier_modulus"]:.3g}|; the threshold is {b["threshold_over_orbit_amplitude"]:.3f} '
                  f'of its angle amplitude')
            print(f'    starts of its shape settle up to {f_lo:.5f} and leave from {f_hi:.5f} times its size: '
                  f'it bounds the basin')
        else:
            print(f'    no periodic orbit at the edge: {b["no_orbit"]}')
    if 'simulation' in res:
        s = res['simulation']
        print(f'  simulation ({args.simulate:g} s, delay {s["delay_s"]:g} s, last half): x p2p '
              f'{100 * s["x_p2p_m"]:.4f} cm, period {s["period_s"]:.5f} s ({s["end_reason"]})')
    if cont:
        c = res['continuation']
        print(f'  continuation in {c["parameter"]} over {c["range"][0]:g}:{c["range"][1]:g}: {c["points"]} orbits on '
              f'{c["branches"]} branches, {c["jacobians"]} Jacobians, {c["seconds"]} s')
        for e in c['events']:
            print(f'    branch {e["branch"]}: {e["event"]} at {e["parameter"]:.5g}' +
                  (f' ({e["multiplier"]})' if 'multiplier' in e else ''))
        if 'plot' in c:
            print(f'  diagram: {c["plot"]}')
    print(f'  written: {out / "orbit.json"}')
    return 0


def loop_variant_options(parser) -> None:
    """--sensors, --smoothing and --cutoff-hz: the loop a scenario is run as (see _sweep_base)."""
    parser.add_argument('--sensors', choices=('exact', 'config'), default='exact',
                        help='exact states as in the paper\'s simulations, or the scenario\'s encoders '
                        '(default %(default)s)')
    parser.add_argument('--smoothing', choices=('none', 'tanh'), default=None,
                        help='override the friction smoothing')
    parser.add_argument('--cutoff-hz', type=float, default=None,
                        help='override the controller\'s velocity filter corner [Hz] (0 = raw difference)')


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
    d.add_argument('--config', default=None, help=f'paper parameter YAML (default {DEFAULT_CONFIG}); with --check '
                   f'a scenario (default {REPO_ROOT / "config" / "default.yaml"})')
    d.add_argument('--data', default=str(DEFAULT_DATA), help='shared data directory (default %(default)s)')
    d.add_argument('--check', action='store_true',
                   help='check the scenario\'s gain instead: predicted hunting (orbit, encoders, describing '
                   'function), linear and effective critical delay, encoder floor, each at friction x0.7 and x1.3; '
                   'one page (check.md, check.png, check.json in --out)')
    d.add_argument('--friction-change', type=float, default=None, metavar='F',
                   help='--check: the friction cases, scale 1 -/+ F of mu_s, mu_c, eps (default 0.3)')
    d.add_argument('--from-ident', metavar='DIR', default=None,
                   help='--check: the friction cases from `./ipfric identify --out DIR`: the identified model and '
                   'its friction coefficients all at -1 and +1 standard error (instead of --friction-change)')
    d.add_argument('--max-delay', type=float, default=0.2,
                   help='--check: the delay scan for the effective critical delay ends here [s] (default %(default)s)')
    d.add_argument('--out', default=None, help='--check: directory of the page (default runs/design-check)')
    s = add('stability', cmd_stability, 'Routh-Hurwitz thresholds in delta and critical delays tau_c')
    s.add_argument('--config', default=str(DEFAULT_CONFIG), help='paper parameter YAML (default %(default)s)')
    m = add('demo', cmd_demo, 'the main job: a closed-loop run of the default scenario through the ROS 2 '
            'nodes (Figure 7: gain (15) on the stick-slip plant), recorded and analysed')
    m.add_argument('--config', default=str(REPO_ROOT / 'config' / 'default.yaml'),
                   help='scenario parameter file (default %(default)s)')
    m.add_argument('--duration', type=float, default=None, help='simulated seconds (default: the file\'s)')
    m.add_argument('--out', default=None, help='run directory (default runs/demo-<time>)')
    r = add('run', cmd_run, 'closed-loop run of the ROS 2 nodes (simulator, controller, recorder) in a fresh '
            'ROS domain on loopback, recorded to a rosbag2 MCAP directory')
    r.add_argument('--config', default=str(Path(DEFAULT_CONFIG).parent / 'default.yaml'),
                   help='scenario parameter file (sim_node / controller_node sections; default %(default)s)')
    r.add_argument('--duration', type=float, default=None,
                   help='simulated seconds (default: the file\'s sim_node duration; 0 = until Ctrl-C)')
    r.add_argument('--out', required=True, help='output directory: bag/, scenario.yaml, logs/, summary.json')
    r.add_argument('--domain', type=int, default=None, help='ROS_DOMAIN_ID (default: a free one in 1..232)')
    r.add_argument('--timeout', type=float, default=None, help='stop the run after this many wall seconds')
    a = add('analyze', cmd_analyze, 'classify recorded runs (settled, limit cycle, irregular, growing, fallen): '
            'amplitude, period, sticking, plots; reads rosbag2 directories, run directories or .mcap files '
            'without ROS, and rig logs (.csv, .mat as identify reads them) per balanced stretch')
    a.add_argument('runs', nargs='+', help='run directory, rosbag2 directory, .mcap file, or a rig log .csv/.mat')
    a.add_argument('--plots', default='runs/analysis', help='directory for PNG figures (default %(default)s)')
    a.add_argument('--no-plots', action='store_true', help='numbers only')
    a.add_argument('--columns', help='rig log: CSV column mapping, e.g. t=time_s,x=cart_m,voltage=u_V,theta=angle_rad')
    a.add_argument('--angle-zero', choices=ANGLE_ZEROS, default='auto',
                   help='rig log: where its angle is zero (default %(default)s: hanging if mostly far from upright)')
    a.add_argument('--max-angle-deg', type=float, default=20.0,
                   help='rig log: balanced while |theta| from upright is below this (default %(default)s deg)')
    a.add_argument('--min-balanced-s', type=float, default=2.0,
                   help='rig log: shortest balanced stretch analysed (default %(default)s s)')
    w = add('sweep', cmd_sweep, 'stability map over the delay tau and the initial angle theta0 (Figures 11-12), '
            'offline physics core, parallel and resumable')
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
    w.add_argument('--scale-sensor', choices=('angle', 'cart', 'both'), default='angle',
                   help='which encoder --resolution-scale scales (default %(default)s)')
    w.add_argument('--threshold', default=None, metavar='LO,HI',
                   help='instead of a map: bisect the initial angle [rad] between a settling LO and a '
                        'cycling HI (bistability, Figure 8b)')
    w.add_argument('--out', required=True, help='directory for cells.csv, map.png, summary.json')
    mc = add('montecarlo', cmd_montecarlo, 'distribution of the hunting (cart and angle peak-to-peak, period, '
             'class) over N runs of a scenario with its parameters drawn at random: relative spreads, or an '
             'identification\'s parameter table with its standard errors; runs.csv, summary.json, histogram.png')
    mc.add_argument('--config', default=str(REPO_ROOT / 'config' / 'default.yaml'),
                    help='scenario whose parameters are drawn (default %(default)s)')
    mc.add_argument('--runs', type=int, default=1000, help='number of runs (default %(default)s)')
    mc.add_argument('--duration', type=float, default=20.0, help='simulated seconds per run (default %(default)s)')
    mc.add_argument('--spread', metavar='NAME=S,...',
                    help='relative 1-sigma spreads of plant or friction coefficients, e.g. mu_s=0.3,mu_c=0.3,eps=0.3 '
                         '(30 %%); each value = nominal * (1 + S z), clipped to its range, mu_c <= mu_s')
    mc.add_argument('--distribution', choices=('normal', 'uniform'), default='normal',
                    help='--spread: z ~ N(0, 1) (S is one sigma) or z ~ U(-1, 1) (S is the half width) '
                         '(default %(default)s)')
    mc.add_argument('--from-ident', metavar='DIR',
                    help='draw the fitted parameters of the final model of `./ipfric identify --out DIR` from '
                         'N(value, std^2), independently (the report has standard errors, no covariance)')
    mc.add_argument('--seed', type=int, default=0, help='seed; run i draws with the seed (seed, i) '
                    '(default %(default)s)')
    mc.add_argument('--sensors', choices=('exact', 'config'), default='config',
                    help='the scenario\'s encoders, or exact states (default %(default)s)')
    mc.add_argument('--workers', type=int, default=None, help='local processes (default: all cores)')
    mc.add_argument('--scheduler', default=None, metavar='ADDRESS',
                    help='run on the Dask cluster whose scheduler listens at ADDRESS (same rows as locally)')
    mc.add_argument('--out', required=True, help='directory for runs.csv, summary.json, histogram.png')
    i = add('identify', cmd_identify, 'identify the cart\'s friction and undeclared effects from measured '
            'data (run bag, CSV, EMPS .mat, or "paper" for Tables 5-6): base fit, residual analysis, '
            'greedy effect search kept only when it pays on validation data; report, export, redesign')
    i.add_argument('data', nargs='?', default='paper', help='run directory / bag / .mcap, .csv (t,x,voltage[,theta]), '
                   'EMPS .mat, or "paper" (default %(default)s)')
    i.add_argument('--validation', help='second file for validation (default: the last part of DATA)')
    i.add_argument('--split', type=float, default=0.6, help='estimation share of DATA when no --validation '
                   '(default %(default)s)')
    i.add_argument('--base', default='exponential', help='declared friction law: viscous, coulomb, exponential '
                   '(the paper\'s values, unless --plant gives them); dynamic for a force-input record such as '
                   'EMPS (default %(default)s)')
    i.add_argument('--free', help='known plant constants to fit too, e.g. M,alpha (default: none; they stay '
                   'as declared)')
    i.add_argument('--effects', help='comma-separated candidate effects (default: the whole library)')
    i.add_argument('--plant', help='the declared model: a scenario, a paper-style YAML, or a file with only '
                   'plant: (default: a bag\'s stored scenario, else Table 1; friction: the paper\'s --base law)')
    i.add_argument('--columns', help='CSV column mapping, e.g. t=time_s,x=cart_m,voltage=u_V,theta=angle_rad')
    i.add_argument('--cart-alone', action='store_true', help='ignore the angle of a bag (pendulum off)')
    i.add_argument('--tables', default=str(Path(DEFAULT_DATA) / 'paper'), help='directory of Tables 5-6 '
                   '(default %(default)s)')
    i.add_argument('--out', default='runs/identify', help='report directory (default %(default)s)')
    i.add_argument('--no-plots', action='store_true', help='no PNG figures')
    i.add_argument('--export', help='write the identified plant and the gain designed on it as a scenario YAML')
    i.add_argument('--scenario', default=str(REPO_ROOT / 'config' / 'default.yaml'),
                   help='settings, Q and R for --export (default %(default)s)')
    i.add_argument('--rig', help='with --export: also write <export>_on_rig.yaml, this scenario\'s rig with '
                   'the new gain')
    i.add_argument('--loop', metavar='SCENARIO', help='closed-loop redesign offline: run SCENARIO, identify on '
                   'its measured data, redesign, run again; prints the amplitudes before and after')
    i.add_argument('--duration', type=float, default=20.0, help='--loop: simulated seconds per run '
                   '(default %(default)s)')
    o = add('orbit', cmd_orbit, 'periodic orbits of the sampled closed loop found directly (shooting on a '
            'Poincare section, Newton, Floquet multipliers), stable and unstable; --continue traces them over '
            'the delay, a gain scale or a friction scale (bifurcation diagram)')
    o.add_argument('--config', default=str(REPO_ROOT / 'config' / 'default.yaml'),
                   help='scenario (default %(default)s)')
    loop_variant_options(o)
    o.add_argument('--continue', dest='continue_', metavar='NAME=START:STOP[:POINTS]',
                   help='trace the branches of orbits over delay [s], gain or friction (multiples of the '
                   'scenario\'s gain, or of its mu_s, mu_c and eps) by continuation, first step 1/(POINTS-1) '
                   'of the range (default 100), e.g. delay=0:0.14')
    o.add_argument('--delay', type=float, default=None,
                   help='feedback delay [s] instead of the scenario\'s; it may fall between samples (the '
                   '--simulate run takes it to whole samples)')
    o.add_argument('--basin', metavar='LO,HI',
                   help='also find the edge of the upright\'s basin over the initial angle in [LO, HI] rad '
                   '(bisection: LO must settle, HI leave) and the unstable orbit the run at the edge lingers on; '
                   'with --continue its branch is traced too')
    o.add_argument('--duration', type=float, default=40.0,
                   help='with --basin: longest run [s] (default %(default)s)')
    o.add_argument('--simulate', type=float, default=120.0,
                   help='also run the loop this many seconds and report its cycle beside the orbit (0 = no)')
    o.add_argument('--scheduler', default=None, metavar='ADDRESS',
                   help='with --continue: compute the Jacobians\' columns on the Dask cluster whose scheduler '
                        'listens at ADDRESS (its workers run this project\'s environment); the same branches '
                        'as on this machine\'s cores')
    o.add_argument('--describing', action='store_true',
                   help='with --continue over delay or gain: the describing-function prediction on the diagram')
    o.add_argument('--no-plots', action='store_true', help='numbers only')
    o.add_argument('--out', default='runs/orbit', help='directory for orbit.json, branches.csv, bifurcation.png '
                   '(default %(default)s)')
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
    except SchedulerError as exc:
        print(f'ipfric {args.command}: {exc}', file=sys.stderr)
        return 2


if __name__ == '__main__':
    sys.exit(main())
