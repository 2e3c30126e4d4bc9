"""``./ipfric design``: the paper's LQR gains, eigenvalues and friction estimates beside the printed
ones; with ``--check``, the design check of a scenario's gain (one page)."""
from __future__ import annotations

import sys
from pathlib import Path

from ..design.paperconfig import DEFAULT_CONFIG, DEFAULT_DATA, load_paper_config
from ..design.reports import design_report
from ..ident.uncertainty import friction_cases as identified_friction_cases
from ..physics.params import ConfigError
from ..run.scenario import DEFAULT_SCENARIO, load_scenario
from ..study.check import MAX_DELAY, check_scenarios, friction_cases
from ..study.check_page import write_check
from .output import eig_text, output_dir, paper_row, print_json, progress_lines

__all__ = ['NAME', 'HELP', 'add_arguments', 'main']

NAME = 'design'
HELP = 'LQR gains of the paper (15), (23), (25), eigenvalues and friction estimates, computed beside the printed values'
CHECK_OUT = 'runs/design-check'


def add_arguments(d) -> None:
    d.add_argument('--config', default=None, help=f'paper parameter YAML (default {DEFAULT_CONFIG}); with --check '
                   f'a scenario (default {DEFAULT_SCENARIO})')
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
    d.add_argument('--max-delay', type=float, default=MAX_DELAY,
                   help='--check: the delay scan for the effective critical delay ends here [s] (default %(default)s)')
    d.add_argument('--out', default=None, help=f'--check: directory of the page (default {CHECK_OUT})')


def check(args) -> int:
    """``--check``: the page of a gain on a scenario (Markdown, PNG, JSON in --out)."""
    config = args.config or str(DEFAULT_SCENARIO)
    if args.from_ident and args.friction_change is not None:
        raise ConfigError('--friction-change with --from-ident: the identification\'s standard errors set the '
                          'friction cases; give one of them')
    output_dir(args.out)
    try:
        base = load_scenario(config)
    except ConfigError as exc:
        raise ConfigError(f'--config: {exc} (with --check: a scenario, e.g. config/default.yaml)') from None
    try:
        cases, axis = (identified_friction_cases(args.from_ident, base) if args.from_ident else
                       friction_cases(base, 0.3 if args.friction_change is None else args.friction_change))
        say = None if args.json else progress_lines('design --check')
        res = check_scenarios(base, cases, axis, args.max_delay, say)
    except ValueError as exc:
        raise ConfigError(str(exc)) from None
    res.update(config=config, scenario=Path(config).stem, from_ident=args.from_ident)
    files = write_check(res, args.out or CHECK_OUT)
    if args.json:
        print_json(res)
        return 0
    print(res['verdict'])
    print(f'page: {files["page"]}\nfigure: {files["figure"]}\nnumbers: {files["json"]} ({res["seconds"]} s)')
    return 0


def print_friction_estimates(fe: dict) -> None:
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


def main(args) -> int:
    if args.check:
        return check(args)
    extra = [o for o, v in (('--out', args.out), ('--from-ident', args.from_ident),
                            ('--friction-change', args.friction_change)) if v is not None]
    if extra:
        raise ConfigError(f'{", ".join(extra)}: only with --check')
    cfg = load_paper_config(args.config or DEFAULT_CONFIG)
    tables = Path(args.data) / 'paper'
    if not tables.is_dir():
        print(f'[design] {tables} is absent: the friction estimates of the appendix tables are left out (--data)',
              file=sys.stderr)
    rep = design_report(cfg, tables if tables.is_dir() else None)
    if args.json:
        print_json(rep)
        return 0
    print(f'LQR gains, V = +K x, Q = diag{cfg.Q}, R = {cfg.R:g}  ({args.config or DEFAULT_CONFIG})')
    for name, e in rep['gains'].items():
        print(paper_row(f'{name} model, eq. {e["equation"]}', e))
        if 'full_gain_with_z' in e:
            print(f'  {"":<34} full gain incl. z (not measured): '
                  + ', '.join(f'{v:.4f}' for v in e['full_gain_with_z']))
    print('Closed-loop eigenvalues, dynamic friction model (eq. 21)')
    for label, e in rep['eigenvalues'].items():
        print(f'  {label:<34} ipfric {eig_text(e["ipfric"])}\n  {"":<34} paper  {eig_text(e["paper"])}')
    print('Controllability rank: ' + ', '.join(f'{k} {v["rank"]}/{v["n_states"]}'
                                               for k, v in rep['controllability_rank'].items()))
    if 'friction_estimates' in rep:
        print_friction_estimates(rep['friction_estimates'])
    return 0
