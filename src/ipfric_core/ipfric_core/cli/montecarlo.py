"""``./ipfric montecarlo``: the hunting's distribution over N runs of a scenario with its parameters
drawn at random (:mod:`ipfric_core.study.montecarlo`)."""
from __future__ import annotations

import math
from pathlib import Path

from ..ident.uncertainty import report_draws
from ..physics.params import ConfigError
from ..run.scenario import DEFAULT_SCENARIO
from ..study.executor import scheduler_address
from ..study.montecarlo import DISTRIBUTIONS, check_duration, check_seed, montecarlo_study, spread_draws
from ..study.variants import SENSORS, load_variant
from .output import output_dir, print_json, progress_counter

__all__ = ['NAME', 'HELP', 'add_arguments', 'main']

NAME = 'montecarlo'
HELP = ('distribution of the hunting (cart and angle peak-to-peak, period, class) over N runs of a scenario with '
        'its parameters drawn at random: relative spreads, or an identification\'s parameter table with its '
        'standard errors; runs.csv, summary.json, histogram.png')


def add_arguments(mc) -> None:
    mc.add_argument('--config', default=str(DEFAULT_SCENARIO),
                    help='scenario whose parameters are drawn (default %(default)s)')
    mc.add_argument('--runs', type=int, default=1000, help='number of runs, 1 .. 1,000,000 (default %(default)s)')
    mc.add_argument('--duration', type=float, default=20.0,
                    help='simulated seconds per run (default %(default)s; at least 10 samples, at most 1e6 s)')
    mc.add_argument('--spread', metavar='NAME=S,...',
                    help='relative 1-sigma spreads of plant or friction coefficients, e.g. mu_s=0.3,mu_c=0.3,eps=0.3 '
                         '(30 %%); each value = nominal * (1 + S z), clipped to its range, mu_c and mu_s in the '
                         'nominal\'s order')
    mc.add_argument('--distribution', choices=DISTRIBUTIONS, default='normal',
                    help='--spread: z ~ N(0, 1) (S is one sigma) or z ~ U(-1, 1) (S is the half width) '
                         '(default %(default)s)')
    mc.add_argument('--from-ident', metavar='DIR',
                    help='draw the fitted parameters of the final model of `./ipfric identify --out DIR` from '
                         'N(value, std^2), independently (the report has standard errors, no covariance)')
    mc.add_argument('--seed', type=int, default=0, help='seed, 0 .. 2**32-1; run i draws with the seed (seed, i) '
                    '(default %(default)s)')
    mc.add_argument('--sensors', choices=SENSORS, default='config',
                    help='the scenario\'s encoders, or exact states (default %(default)s)')
    mc.add_argument('--workers', type=int, default=None, help='local processes (default: all cores)')
    mc.add_argument('--scheduler', default=None, metavar='ADDRESS',
                    help='run on the Dask cluster whose scheduler listens at ADDRESS (same rows as locally)')
    mc.add_argument('--out', required=True, help='directory for runs.csv, summary.json, histogram.png')


def main(args) -> int:
    if (args.spread is None) == (args.from_ident is None):
        raise ConfigError('give either --spread NAME=S,... (relative spreads) or --from-ident DIR (an '
                          'identification\'s parameter table)')
    output_dir(args.out)
    check_seed(args.seed)
    if args.scheduler:
        scheduler_address(args.scheduler)
    base = load_variant(args.config, args.sensors)
    check_duration(args.duration, base)
    draw, drawn = (spread_draws(base, args.spread, args.seed, args.distribution) if args.spread is not None
                   else report_draws(args.from_ident, base, args.seed))
    title = f'{Path(args.config).stem}: {args.runs} runs of {args.duration:g} s, ' + (
        f'spread {args.spread} ({args.distribution})' if args.spread else f'from {args.from_ident}')
    summary = montecarlo_study(draw, {'config': args.config, 'seed': args.seed, 'sensors': args.sensors,
                                      'drawn': drawn}, args.runs, args.duration, args.out, title, args.workers,
                               args.scheduler, None if args.json else progress_counter('montecarlo', 'runs'))
    if args.json:
        print_json(summary)
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
    print(f'summary: {summary["json"]}\nruns: {summary["csv"]}\nfigure: {summary["figure"]}')
    return 0
