"""``./ipfric stability``: the Routh-Hurwitz thresholds in delta and the critical delays tau_c beside the
printed ones."""
from __future__ import annotations

from ..design.paperconfig import DEFAULT_CONFIG, load_paper_config
from ..design.reports import stability_report
from .output import paper_row, print_json

__all__ = ['NAME', 'HELP', 'add_arguments', 'main']

NAME = 'stability'
HELP = 'Routh-Hurwitz thresholds in delta and critical delays tau_c'


def add_arguments(s) -> None:
    s.add_argument('--config', default=str(DEFAULT_CONFIG), help='paper parameter YAML (default %(default)s)')


def main(args) -> int:
    rep = stability_report(load_paper_config(args.config))
    if args.json:
        print_json(rep)
        return 0
    rh = rep['routh_hurwitz_gain_15_exponential']
    print('Gain (15) on the exponential model, sgn(v) ~ tanh(delta v), eq. (19):')
    print(paper_row('two RHP roots for delta >', rh['unstable_above_delta'], '{:.2f}'))
    print(paper_row('complex RHP pair up to delta', rh['complex_pair_until_delta'], '{:.2f}'))
    print('Critical delay tau_c of eq. (27):')
    for name, e in rep['critical_delay_s'].items():
        print(paper_row(f'{name}', e))
        if 'with_full_gain_incl_z' in e:
            print(f'  {"":<34} with the full gain incl. z: {e["with_full_gain_incl_z"]:.4f}')
    return 0
