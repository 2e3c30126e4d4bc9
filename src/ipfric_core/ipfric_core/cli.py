"""Command line of ipfric: ``./ipfric <command> [--json]``."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from .params import ConfigError
from .paperconfig import DEFAULT_CONFIG, DEFAULT_DATA, load_paper_config


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
