"""Identification: loaders, the effect search on data with undeclared effects, EMPS, the
paper's tables and the closed-loop redesign (no ROS)."""
import json
from dataclasses import replace

import numpy as np
import pytest

from ipfric_core.cli import main
from ipfric_core.ident.records import load_csv, load_emps, write_csv
from ipfric_core.design.estimation import load_table5, load_table6
from ipfric_core.ident.excitation import cart_alone_run, dithered_run
from ipfric_core.ident.identify import errors, identify, identify_steady
from ipfric_core.physics.params import ConfigError, FrictionParams, PlantParams
from ipfric_core.ident.redesign import close_the_loop
from ipfric_core.physics.rig import PlantTruth
from ipfric_core.run.scenario import load_scenario
from conftest import ROOT

PLANT = PlantParams()
# Table 2: the cart alone with Coulomb and static friction
TRACK = FrictionParams(model='coulomb', eps=2.3156, mu_s=0.08328, mu_c=0.04287)
FN = PLANT.M * PLANT.g


@pytest.fixture(scope='module')
def clean():
    return cart_alone_run(PLANT, TRACK, PlantTruth(), 12.0)


def search(rec, base='coulomb'):
    est, val = rec.split(0.6)
    res = identify(est, val, base)
    return res['fit'], res


# -- loaders ------------------------------------------------------------------------------

def test_csv_round_trip_and_column_mapping(tmp_path, clean):
    path = write_csv(tmp_path / 'run.csv', clean)
    rec = load_csv(path, PLANT)
    assert np.allclose(rec.x, clean.x) and np.allclose(rec.u, clean.u) and rec.theta is None
    text = path.read_text().replace('t,x,voltage', 'time_s,cart_m,u_V', 1)
    (tmp_path / 'mapped.csv').write_text(text)
    rec2 = load_csv(tmp_path / 'mapped.csv', PLANT, {'t': 'time_s', 'x': 'cart_m', 'voltage': 'u_V'})
    assert np.allclose(rec2.t, clean.t)
    assert rec.gain == PLANT.alpha and rec.normal_force == pytest.approx(FN)


@pytest.mark.parametrize('mangle, message', [
    (lambda d: d[:, [0, 2]], "missing column 'x'"),
    (lambda d: d[[1, 0] + list(range(2, len(d)))], 'time is not increasing'),
    (lambda d: np.where(np.arange(d.size).reshape(d.shape) == 3 * 50 + 1, np.nan, d), 'NaN'),
    (lambda d: d[:100], 'too short'),
    (lambda d: d * np.array([1.0, 1000.0, 1.0]), 'expected metres'),
])
def test_csv_bad_input_is_refused_with_the_problem(tmp_path, clean, mangle, message):
    data = mangle(np.column_stack([clean.t, clean.x, clean.u]))
    header = 't,voltage' if data.shape[1] == 2 else 't,x,voltage'
    np.savetxt(tmp_path / 'bad.csv', data, delimiter=',', header=header, comments='')
    with pytest.raises(ConfigError, match=message):
        load_csv(tmp_path / 'bad.csv', PLANT)


def test_angle_in_degrees_and_uneven_sampling_are_refused(tmp_path, clean):
    deg = np.column_stack([clean.t, clean.x, clean.u, np.full(len(clean.t), 15.0)])
    np.savetxt(tmp_path / 'deg.csv', deg, delimiter=',', header='t,x,voltage,theta', comments='')
    with pytest.raises(ConfigError, match='degrees'):
        load_csv(tmp_path / 'deg.csv', PLANT)
    uneven = np.column_stack([clean.t ** 1.2, clean.x, clean.u])
    np.savetxt(tmp_path / 'uneven.csv', uneven, delimiter=',', header='t,x,voltage', comments='')
    with pytest.raises(ConfigError, match='not evenly spaced'):
        load_csv(tmp_path / 'uneven.csv', PLANT)


def test_emps_loader(data_dir):
    rec = load_emps(data_dir / 'emps' / 'DATA_EMPS.mat')
    assert len(rec.t) == 24841 and rec.dt == pytest.approx(1e-3, rel=1e-4)
    assert rec.gain == pytest.approx(35.1507, rel=1e-5) and rec.back_emf == 0.0


# -- undeclared effects: the right one is found, nothing on clean data ---------------------

def test_clean_data_gets_no_effect_and_the_declared_parameters(clean):
    fit, res = search(clean)
    assert fit.active == ('coulomb',), res['tried']
    p = fit.params
    assert p['mass'] == pytest.approx(PLANT.M, rel=0.02)
    assert p['eps'] == pytest.approx(TRACK.eps, rel=0.03)
    assert p['Fc'] / FN == pytest.approx(TRACK.mu_c, rel=0.03)
    assert p['Fc'] + p['Fs_excess'] <= TRACK.mu_s * FN * 1.02  # stuck samples bound Fs from below only


# effect, truth, (parameter, true value, relative tolerance)
CASES = [
    ('cogging', dict(cogging_N=0.3, cogging_period_m=0.02), [('cog_sin', -0.3, 0.03), ('cog_period', 0.02, 0.01)]),
    ('deadzone', dict(deadzone_V=0.3), [('dz', 0.3, 0.05)]),
    ('asymmetry', dict(asymmetry_N=0.15), [('dFc', 0.15, 0.05)]),
    ('delay', dict(input_delay_s=0.02), [('delay', 0.02, 0.03)]),
    ('backlash', dict(backlash_m=0.002), [('gap', 0.002, 0.05)]),
]


@pytest.mark.parametrize('effect, truth, expect', CASES, ids=[c[0] for c in CASES])
def test_undeclared_effect_is_found_with_its_parameters(effect, truth, expect):
    rec = cart_alone_run(PLANT, TRACK, PlantTruth(**truth), 12.0)
    fit, res = search(rec)
    assert fit.active == ('coulomb', effect), res['tried']
    for name, value, tol in expect:
        assert fit.params[name] == pytest.approx(value, rel=tol), name
    assert fit.params['Fc'] / FN == pytest.approx(TRACK.mu_c, rel=0.05)
    pv = res['prepared'][1]
    assert errors(pv, fit.params, fit.active)['rms'] < 0.3 * errors(pv, res['base_fit'].params, ('coulomb',))['rms'] \
        or effect == 'backlash'


def test_angle_sensor_bias_found_in_dithered_closed_loop(tmp_path):
    sc = load_scenario(ROOT / 'config' / 'fig7_old_gain_viscous.yaml')
    biased = dithered_run(replace(sc, truth=PlantTruth(bias_theta_rad=0.01)), 12.0, 1.0)
    back = load_csv(write_csv(tmp_path / 'pendulum.csv', biased), PLANT)
    assert np.allclose(back.theta, biased.theta) and back.normal_force == pytest.approx(PLANT.normal_force)
    fit, res = search(biased, 'viscous')
    assert fit.active == ('sensor_bias',), res['tried']
    assert fit.params['theta_bias'] == pytest.approx(0.01, rel=0.05)
    fit0, res0 = search(dithered_run(sc, 12.0, 1.0), 'viscous')
    assert fit0.active == (), res0['tried']
    assert fit0.params['eps'] == pytest.approx(sc.friction.eps, rel=0.05)


# -- measured data --------------------------------------------------------------------------

@pytest.mark.slow
def test_emps_beats_the_published_reference_models(data_dir, tmp_path):
    d = data_dir / 'emps'
    assert main(['identify', str(d / 'DATA_EMPS.mat'), '--validation', str(d / 'DATA_EMPS_PULSES.mat'),
                 '--base', 'coulomb', '--effects', 'asymmetry,stribeck,presliding,offset',
                 '--out', str(tmp_path), '--no-plots']) == 0
    r = json.loads((tmp_path / 'result.json').read_text())
    assert r['effects_added'][0] == 'asymmetry'
    before, after = r['error_before'], r['error_after']
    assert after['estimation']['relative_percent'] < 3.0   # published: 4.08 symmetric, 3.11 asymmetric
    assert after['validation']['relative_percent'] < 3.11
    assert after['validation']['rms'] < 0.5 * before['validation']['rms']
    assert 94 < r['params']['mass']['value'] < 96
    assert {t['name'] for t in r['effects_tried'] if not t['kept']} <= {'offset', 'presliding', 'stribeck'}


def test_paper_tables_through_the_force_balance(data_dir, paper_cfg):
    d = data_dir / 'paper'
    V, v, *_ = load_table5(d / 'table5_constant_voltage.csv')
    r = identify_steady(paper_cfg.plant, V, v, load_table6(d / 'table6_breakaway_voltage.csv'))
    assert r['mu_s'] == pytest.approx(0.08328, abs=5e-5)
    assert r['mu_c'] == pytest.approx(0.04287, abs=r['mu_c_std'])   # paper, within one standard error
    assert r['eps'] == pytest.approx(2.3156, abs=r['eps_std'])
    assert abs(r['residual_curvature_N']) < r['sliding_rms_N']      # no Stribeck curve in 0.1-0.4 m/s


# -- closing the loop ----------------------------------------------------------------------

@pytest.mark.slow
def test_redesign_on_identified_stick_slip_shrinks_the_limit_cycle(tmp_path):
    out = close_the_loop(ROOT / 'config' / 'fig7_old_gain_exponential.yaml', tmp_path, 20.0, plots=False)
    assert out['before']['class'] == 'limit_cycle'
    ident = out['identified']
    assert ident['effects_added'][0] == 'coulomb'
    assert 0.03 < ident['friction']['mu_c'] < 0.0861          # true mu_c 0.04287, mu_s 0.0861
    assert out['after']['end_reason'] == 'duration'
    assert out['after']['x_p2p_m'] < 0.5 * out['before']['x_p2p_m']
    sc = load_scenario(out['export']['scenario'])
    assert sc.friction.model in ('coulomb', 'exponential', 'dynamic')
    assert list(sc.controller.gain) == pytest.approx(out['gain_after'])


def test_cli_csv_report_and_export(tmp_path, clean, capsys):
    csv = write_csv(tmp_path / 'cart.csv', clean)
    assert main(['identify', str(csv), '--base', 'coulomb', '--out', str(tmp_path / 'rep'), '--json',
                 '--export', str(tmp_path / 'identified.yaml')]) == 0
    r = json.loads(capsys.readouterr().out)
    for key in ('base_model', 'effects_added', 'params', 'error_before', 'error_after', 'residual_white_before',
                'residual_white_after', 'effects_tried'):
        assert key in r
    assert set(r['error_after']) == {'estimation', 'validation'}
    assert {'rms', 'relative_percent'} <= set(r['error_after']['validation'])
    for name in ('report.md', 'fit.png', 'residual.png', 'autocorrelation.png'):
        assert (tmp_path / 'rep' / name).stat().st_size > 0
    sc = load_scenario(tmp_path / 'identified.yaml')
    assert sc.friction.mu_c == pytest.approx(TRACK.mu_c, rel=0.05)
    assert main(['identify', str(csv), '--effects', 'friction_wobble', '--out', str(tmp_path)]) == 2
    assert 'friction_wobble' in capsys.readouterr().err
