"""./ipfric design --check: the page of a gain on a scenario, against the orbit and runs it reports."""
from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from ipfric_core.cli import main
from ipfric_core.run.scenario import load_scenario
from ipfric_core.study.check import settled_cycle
from ipfric_core.study.orbit import find_orbit, loop_numbers
from ipfric_core.study.variants import exact_sensors

ROOT = Path(__file__).resolve().parents[2]
FIG7 = ROOT / 'config' / 'fig7_old_gain_exponential.yaml'


def exact_loop(scn, delay=None):
    scn = exact_sensors(scn)
    return loop_numbers(scn.make_rig().loop_spec(), scn.make_controller().loop_spec(), delay)


@pytest.fixture(scope='module')
def check(tmp_path_factory):
    """The check of Figure 7's gain, delay scan to 100 ms (the loss is near 83 ms)."""
    out = tmp_path_factory.mktemp('check')
    assert main(['design', '--check', '--config', str(FIG7), '--max-delay', '0.1', '--out', str(out)]) == 0
    return out, json.loads((out / 'check.json').read_text())


def test_the_files_are_written(check):
    out, res = check
    assert (out / 'check.png').stat().st_size > 20_000
    page = (out / 'check.md').read_text()
    assert page.startswith('# Design check: fig7_old_gain_exponential') and '](check.png)' in page
    assert res['verdict'] in page and '## Sensitivity' in page and '## Encoder floor' in page
    assert [c['label'] for c in res['cases']] == ['friction x0.7', 'scenario', 'friction x1.3']


def test_the_page_shows_the_orbit(check):
    out, res = check
    orbit = find_orbit(exact_loop(load_scenario(FIG7)))
    h = res['cases'][res['nominal']]['hunting']['exact']
    assert h['source'] == 'orbit' and h['orbit']['stable']
    assert h['x_p2p_m'] == pytest.approx(orbit.x_p2p, rel=1e-9)
    assert h['period_s'] == pytest.approx(orbit.period, rel=1e-9)
    assert f'| exact | {100 * orbit.x_p2p:.4g} cm |' in (out / 'check.md').read_text()
    # the encoders make the cycle irregular: no orbit, the run's numbers instead
    assert res['cases'][res['nominal']]['hunting']['encoders']['source'] == 'run'


def test_more_friction_hunts_larger_and_holds_longer(check):
    _, res = check
    n = [c['numbers'] for c in res['cases']]
    for key in ('x_p2p_exact_m', 'x_p2p_describing_m', 'x_p2p_encoders_m', 'holds_to_exact_s', 'tau_c_sliding_s'):
        assert n[0][key] < n[1][key] < n[2][key], key
    assert n[0]['period_exact_s'] > n[1]['period_exact_s'] > n[2]['period_exact_s']   # sticks shorter
    assert n[1]['tau_c_tanh_s'] == 0.0          # gain (15): the tanh-smoothed upright is unstable
    assert 0.0 < n[1]['floor_x_p2p_m'] < 0.25 * n[1]['x_p2p_exact_m']


def test_the_effective_delay_is_the_edge_of_holding(check):
    _, res = check
    e = res['cases'][res['nominal']]['effective_delay']['exact']
    assert e['small_to_s'] < e['holds_to_s'] < e['lost_from_s'] <= e['holds_to_s'] + e['tolerance_s']
    scn = load_scenario(FIG7)
    assert settled_cycle(exact_loop(scn, e['holds_to_s']))['holds']
    assert not settled_cycle(exact_loop(scn, e['lost_from_s']))['holds']


def identification(path: Path) -> Path:
    """A result.json as `./ipfric identify --out DIR` writes it (Fc, Fs_excess, eps with standard errors)."""
    params = [{'name': n, 'value': v, 'std': None, 'unit': '', 'fitted': False}
              for n, v in (('M', 0.815), ('m', 0.21), ('l', 0.305), ('alpha', 1.7189), ('beta', 7.682))]
    params += [{'name': n, 'value': v, 'std': s, 'unit': '', 'fitted': True}
               for n, v, s in (('Fc', 0.4033, 0.04), ('Fs_excess', 0.4602, 0.04), ('eps', 3.311, 0.5),
                               ('v_s', 0.0972, float('nan')))]
    path.mkdir(parents=True)
    (path / 'result.json').write_text(json.dumps({
        'data': {'pendulum': True, 'sample_period_s': 0.001},
        'ladder': [{'step': 'refit', 'effects': [], 'params': params}],
        'identified': {'plant': {'M': 0.815, 'm': 0.21, 'l': 0.305, 'g': 9.8, 'alpha': 1.7189, 'beta': 7.682},
                       'friction': {'model': 'exponential', 'eps': 3.311, 'mu_s': 0.0860, 'mu_c': 0.0401,
                                    'v_s': 0.0972, 'gamma': 2.0, 'smoothing': 'none', 'delta': 100.0}}}))
    return path


def test_cases_from_an_identification(tmp_path, capsys):
    ident = identification(tmp_path / 'ident')
    assert main(['design', '--check', '--config', str(FIG7), '--from-ident', str(ident), '--max-delay', '0.02',
                 '--json', '--out', str(tmp_path / 'out')]) == 0
    res = json.loads(capsys.readouterr().out)
    assert [c['value'] for c in res['cases']] == [-1, 0, 1] and res['cases'][1]['label'] == 'identified'
    mu_c = [c['friction']['mu_c'] for c in res['cases']]
    assert mu_c[1] == pytest.approx(0.4033 / load_scenario(FIG7).plant.normal_force)
    assert mu_c[0] < mu_c[1] < mu_c[2] and res['cases'][2]['friction']['v_s'] == 0.0972   # no SE: kept
    x = [c['numbers']['x_p2p_exact_m'] for c in res['cases']]
    assert x[0] < x[1] < x[2]
    assert (tmp_path / 'out' / 'check.md').exists()


@pytest.mark.parametrize('args, option', [
    (['--check', '--friction-change', '1.5'], '--friction-change'),
    (['--check', '--max-delay', '-0.1'], '--max-delay'),
    (['--check', '--config', 'no/such.yaml'], '--config'),
    (['--check', '--config', str(ROOT / 'config' / 'paper.yaml')], '--config'),
    (['--check', '--from-ident', 'no/such/dir'], '--from-ident'),
    (['--check', '--from-ident', 'x', '--friction-change', '0.2'], '--friction-change'),
    (['--from-ident', 'x'], '--from-ident'),
])
def test_bad_input_names_the_option(args, option, tmp_path, capsys):
    assert main(['design', *args, '--out', str(tmp_path)]) == 2
    assert option in capsys.readouterr().err


def test_a_floor_needs_the_viscous_loop_to_rest():
    """The encoder floor is quantization's only when the loop without Coulomb friction rests with exact sensors."""
    def viscous(scn):
        return replace(scn, friction=scn.friction.replace(model='viscous'))
    assert settled_cycle(exact_loop(viscous(load_scenario(FIG7))))['behaviour'] == 'rests'
    # delay 20 ms beyond the sliding tau_c of the new gain (15.4 ms): it hunts with exact sensors too
    tau20 = load_scenario(ROOT / 'config' / 'delay_exponential_tau20ms.yaml')
    assert settled_cycle(exact_loop(viscous(tau20)))['behaviour'] == 'hunts'


def test_a_file_for_out_is_refused_before_any_work(tmp_path, capsys):
    f = tmp_path / 'page'
    f.write_text('x')
    assert main(['design', '--check', '--out', str(f)]) == 2
    err = capsys.readouterr().err
    assert f'--out: {f} is a file; allowed: a directory (new or existing)' in err and '[design --check]' not in err
