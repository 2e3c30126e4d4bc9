"""Monte Carlo over parameter uncertainty: seeded draws, the summary, the identification's table, the CLI."""
import csv
import json
import math
from dataclasses import replace
from pathlib import Path

import pytest

from ipfric_core.cli import main
from ipfric_core.ident.uncertainty import load_report, report_draw
from ipfric_core.physics.params import ConfigError
from ipfric_core.run.scenario import load_scenario
from ipfric_core.study.montecarlo import parse_spread, run_montecarlo, spread_draw, summarize

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope='module')
def fig7():
    return load_scenario(ROOT / 'config' / 'fig7_old_gain_exponential.yaml')


def test_draws_depend_on_seed_and_run_only(fig7):
    spread = parse_spread('mu_s=0.3,mu_c=0.3,eps=0.1')
    values, scn = spread_draw(fig7, spread, 7, 3)
    assert spread_draw(fig7, spread, 7, 3)[0] == values                  # same seed and index, same draw
    assert spread_draw(fig7, spread, 8, 3)[0] != values
    assert scn.friction.mu_s == values['mu_s'] and scn.friction.eps == values['eps']
    assert scn.controller == fig7.controller and scn.sim == fig7.sim
    draws = [spread_draw(fig7, {'mu_s': 1.0, 'mu_c': 1.0}, 0, i)[1].friction for i in range(200)]
    assert all(0.0 <= f.mu_c <= f.mu_s for f in draws)                  # clipped to the range, mu_c <= mu_s
    rising = replace(fig7, friction=replace(fig7.friction, mu_s=0.03, mu_c=0.05))   # a level rising with speed
    draws = [spread_draw(rising, {'mu_s': 1.0, 'mu_c': 1.0}, 0, i)[1].friction for i in range(200)]
    assert all(f.mu_c >= f.mu_s for f in draws) and sum(f.mu_c > f.mu_s for f in draws) > 100   # its order kept
    keys = {tuple(spread_draw(fig7, {'mu_s': 1.0}, 0, i)[0]) for i in range(200)}
    assert keys == {('mu_s', 'mu_c')}            # a spread of mu_s alone: every run's row holds the mu_c it ran
    uniform = [spread_draw(fig7, {'eps': 0.3}, 0, i, 'uniform')[0]['eps'] for i in range(200)]
    assert 0.7 * fig7.friction.eps <= min(uniform) and max(uniform) <= 1.3 * fig7.friction.eps
    with pytest.raises(ConfigError, match='--spread: .mu_k. is not a coefficient'):
        parse_spread('mu_k=0.3')
    with pytest.raises(ConfigError, match='--spread: mu_s = 2'):
        parse_spread('mu_s=2')


def test_runs_and_summary(fig7):
    spread = {'mu_s': 0.3, 'mu_c': 0.3}
    rows = run_montecarlo(lambda i: spread_draw(fig7, spread, 0, i), 6, 8.0, workers=2)
    assert [r['run'] for r in rows] == list(range(6))
    again = run_montecarlo(lambda i: spread_draw(fig7, spread, 0, i + 4), 2, 8.0, workers=1)
    assert [{**r, 'run': r['run'] + 4} for r in again] == rows[4:]      # a run depends only on its draw
    s = summarize(rows)
    assert sum(s['fraction'].values()) == pytest.approx(1.0)
    assert s['hunting_fraction'] == 1.0                                  # gain (15) hunts on this plant
    q = s['true_x_p2p_m']
    assert 0.005 < q['q05'] <= q['q50'] <= q['q95'] < 0.04 and q['runs'] == 6
    assert 1.5 < s['period_s']['q50'] < 4.0


def identification(tmp_path: Path) -> Path:
    """A result.json as `./ipfric identify --out DIR` writes it (ladder's final step: refit)."""
    params = [{'name': n, 'value': v, 'std': None, 'unit': '', 'fitted': False}
              for n, v in (('M', 0.815), ('m', 0.21), ('l', 0.305), ('alpha', 1.7189), ('beta', 7.682))]
    params += [{'name': 'Fc', 'value': 0.4033, 'std': 0.0193, 'unit': 'N', 'fitted': True},
               {'name': 'Fs_excess', 'value': 0.4602, 'std': 0.0197, 'unit': 'N', 'fitted': True},
               {'name': 'eps', 'value': 3.311, 'std': 0.509, 'unit': 'N s/m', 'fitted': True},
               {'name': 'v_s', 'value': 0.0972, 'std': float('nan'), 'unit': 'm/s', 'fitted': True}]
    result = {'data': {'pendulum': True, 'sample_period_s': 0.001},
              'ladder': [{'step': 'refit', 'effects': [], 'params': params}],
              'identified': {'plant': {'M': 0.815, 'm': 0.21, 'l': 0.305, 'g': 9.8, 'alpha': 1.7189, 'beta': 7.682},
                             'friction': {'model': 'exponential', 'eps': 3.311, 'mu_s': 0.0860, 'mu_c': 0.0401,
                                          'v_s': 0.0972, 'gamma': 2.0, 'smoothing': 'none', 'delta': 100.0},
                             'normal_force_N': 10.045, 'plant_truth': {}}}
    tmp_path.mkdir(parents=True, exist_ok=True)
    (tmp_path / 'result.json').write_text(json.dumps(result))
    return tmp_path


def test_draws_from_an_identification(fig7, tmp_path):
    model, std, dt = load_report(identification(tmp_path))
    assert set(std) == {'Fc', 'Fs_excess', 'eps'} and dt == 0.001         # v_s has no finite standard error
    values, scn = report_draw(model, std, dt, fig7, 0, 0)
    fn = fig7.plant.normal_force
    assert scn.friction.mu_c == pytest.approx(values['Fc'] / fn)
    assert scn.friction.mu_s == pytest.approx((values['Fc'] + values['Fs_excess']) / fn)
    assert scn.friction.v_s == 0.0972 and scn.controller == fig7.controller
    eps = [report_draw(model, std, dt, fig7, 0, i)[0]['eps'] for i in range(400)]
    assert sum(eps) / len(eps) == pytest.approx(3.311, abs=3 * 0.509 / math.sqrt(400))
    with pytest.raises(ConfigError, match='--from-ident'):
        load_report(tmp_path / 'missing')


def test_command_writes_summary_runs_and_histogram(tmp_path, capsys):
    out = tmp_path / 'mc'
    ident = identification(tmp_path / 'ident')
    assert main(['montecarlo', '--config', str(ROOT / 'config' / 'default.yaml'), '--runs', '4', '--duration', '6',
                 '--from-ident', str(ident), '--workers', '1', '--json', '--out', str(out)]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s['runs'] == 4 and s['drawn']['std'].keys() == {'Fc', 'Fs_excess', 'eps'}
    with open(out / 'runs.csv') as fh:
        rows = list(csv.DictReader(fh))
    assert [r['run'] for r in rows] == ['0', '1', '2', '3'] and {'Fc', 'class', 'period_s'} <= set(rows[0])
    assert (out / 'histogram.png').stat().st_size > 10_000


@pytest.mark.parametrize('args, field', [
    (['--runs', '0', '--spread', 'mu_s=0.3'], '--runs'),
    (['--runs', '1000000000000', '--spread', 'mu_s=0.3'], 'allowed 1 .. 1,000,000'),   # before any draw
    (['--spread', 'mu_s=0.3', '--duration', '-1'], '--duration'),
    (['--spread', 'friction=0.3'], '--spread'),
    ([], '--spread'),
    (['--spread', 'mu_s=0.3', '--from-ident', 'x'], '--from-ident'),
])
def test_bad_input_names_the_field(args, field, tmp_path, capsys):
    assert main(['montecarlo', *args, '--out', str(tmp_path)]) == 2
    assert field in capsys.readouterr().err


def test_a_file_for_out_is_refused_before_any_work(tmp_path, capsys):
    f = tmp_path / 'mc'
    f.write_text('x')
    assert main(['montecarlo', '--spread', 'mu_s=0.3', '--runs', '2', '--out', str(f)]) == 2
    assert f'--out: {f} is a file; allowed: a directory (new or existing)' in capsys.readouterr().err


@pytest.mark.parametrize('args, words', [
    (['--seed', '-1'], ['--seed', '-1', '0 .. 4294967295']),
    (['--seed', str(2**32)], ['--seed', '4294967296', '0 .. 4294967295']),
    (['--duration', '1e-9'], ['--duration', '1e-09', 'allowed 0.01 .. 1e+06 s', '10 samples']),
    (['--duration', 'nan'], ['--duration', 'nan']),
])
def test_bad_seed_and_duration_are_refused_with_the_range(args, words, tmp_path, capsys):
    assert main(['montecarlo', '--spread', 'mu_s=0.3', '--runs', '2', *args, '--out', str(tmp_path / 'o')]) == 2
    err = capsys.readouterr().err
    assert all(w in err for w in words), err
    assert not (tmp_path / 'o').exists()


def _broken(result: dict, change: str) -> None:
    if change == 'no ladder':
        del result['ladder']
    elif change == 'empty ladder':
        result['ladder'] = []
    elif change == 'no plant':
        del result['identified']['plant']
    elif change == 'dt 0':
        result['data']['sample_period_s'] = 0
    elif change == 'M negative':
        result['identified']['plant']['M'] = -0.8
    elif change == 'nan param':
        result['ladder'][-1]['params'][2]['value'] = float('nan')
    elif change == 'no data':
        del result['data']


@pytest.mark.parametrize('change, words', [
    ('no ladder', ['no ladder']),
    ('empty ladder', ['ladder is empty']),
    ('no plant', ['identified.plant is missing']),
    ('dt 0', ['data.sample_period_s 0 is invalid', '(0, 1] s']),
    ('M negative', ['identified.plant.M', '-0.8', '(0, 1000] kg']),
    ('nan param', ['ladder parameter l = nan', 'allowed']),
    ('no data', ['data section is missing']),
])
def test_a_broken_identification_is_refused_naming_file_and_field(change, words, tmp_path, capsys):
    folder = identification(tmp_path / 'ident')
    result = json.loads((folder / 'result.json').read_text())
    _broken(result, change)
    (folder / 'result.json').write_text(json.dumps(result))
    assert main(['montecarlo', '--from-ident', str(folder), '--runs', '2', '--out', str(tmp_path / 'o')]) == 2
    err = capsys.readouterr().err
    assert str(folder / 'result.json') in err and all(w in err for w in words), err
    assert 'Traceback' not in err
