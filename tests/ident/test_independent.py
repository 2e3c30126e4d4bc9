"""Identification on data ipfric did not make: the independent rig simulator of
tests/independent (its own integrator and effect formulas, the paper's plant and Table-3
friction with true stick-slip, encoder quantization), one undeclared effect per file, the
same command for every file, and a second rig with other constants, 5 ms sampling, sample
overruns and an angle measured from hanging.

Each case asserts the effect kept (nothing on the clean files), its parameters against the
truth, that no fitted parameter ends on a bound, and that the simulation error falls; the
drive play (a two-mass drive) also that --export writes it.
"""
import json
import math

import numpy as np
import pytest
from independent import rigsim

from ipfric_core.analysis.records import load
from ipfric_core.cli import main
from ipfric_core.ident.effects import PARAMS
from ipfric_core.ident.ladder import run_ladder
from ipfric_core.ident.model import load_declared
from ipfric_core.run.scenario import load_scenario


def cogging_amplitude(p):
    return math.hypot(p['cogging_sin_N'], p['cogging_cos_N'])


# case, effects kept, {parameter: (true value, absolute tolerance)}
CASES = [
    ('cart_none', (), {'Fc': (0.3425, 0.02), 'eps': (3.0, 0.2)}),
    ('cart_deadzone', ('deadzone',), {'deadzone_V': (0.3, 0.03)}),
    ('cart_cogging', ('cogging',), {'cogging_period_m': (0.010, 0.0005), cogging_amplitude: (0.3, 0.05)}),
    ('cart_asymmetry', ('asymmetry',), {'asymmetry': (0.4, 0.05)}),
    ('cart_delay', ('delay',), {'input_delay_s': (0.010, 0.003)}),
    ('loop_none', (), {}),
    ('loop_deadzone', ('deadzone',), {'deadzone_V': (0.3, 0.06)}),
    ('loop_cogging', ('cogging',), {'cogging_period_m': (0.010, 0.001), cogging_amplitude: (0.3, 0.08)}),
    ('loop_asymmetry', ('asymmetry',), {'asymmetry': (0.4, 0.1)}),
    ('loop_delay', ('delay',), {'input_delay_s': (0.010, 0.004)}),
    ('loop_bias', ('sensor_bias',), {'bias_theta_rad': (0.005, 0.002)}),
    # drive play 1 mm, motor side 0.2 kg, contact 2e5 N/m (rigsim.EFFECTS['backlash']): the play within
    # two encoder counts (0.09 mm), the motor side within 10 %. The contact's stiffness and damping are
    # not compared: in the closed loop the simulated error is rough in every parameter (the contact
    # rings through many knocks: forward and backward differences disagree) and the fit stays at the
    # grid point it starts from (100 or 200 Hz, the two fit the estimation data equally well; which
    # one won used to depend on a race between threads); the report flags them (ROUGH below)
    ('loop_backlash', ('drive_backlash',), {'drive_backlash_m': (1e-3, 9e-5), 'drive_mass_kg': (0.2, 0.02)}),
]
#: cases the final model does not explain down to the encoders' floor, and the most it may leave [% of the
#: motion]: in the closed loop with a drive play even the generator's own values leave 1.07 counts (1.8 %)
#: against a floor of 0.34 (0.56 %; 0.93 counts before the drive's finer steps at its contact's edges, 37ceb16):
#: the contact rings at 180 Hz and two integrators of its knocks part
NOT_EXPLAINED = {'loop_backlash': 5.0}
#: parameters whose simulated error must be reported rough (their errors from a scan, not the Jacobian)
ROUGH = {'loop_backlash': {'drive_stiffness_N_per_m', 'drive_damping_Ns_per_m'}}


@pytest.fixture(scope='module')
def data(tmp_path_factory):
    """Every case written once as a CSV by the independent simulator."""
    out = tmp_path_factory.mktemp('independent')
    paths = {}
    for name, *_ in CASES + [('ip02_cart',), ('ip02_loop_hanging',), ('cart_jitter',)]:
        paths[name] = rigsim.write_case(name, out)      # 90 s cart alone, 30 s closed loop
    paths['cart_backlash'] = rigsim.write_case('cart_backlash', out, duration=45.0)   # the play shows in 45 s
    return paths


#: the cases of the default run (a clean record and an effect for the closed loop, a clean cart); the others
#: are marked long (the default run's campaign cases cover an offset and a spring on other rigs:
#: tests/ident/test_campaign_fixed.py)
IN_SUITE = ('cart_none', 'loop_none', 'loop_delay')


@pytest.mark.slow
@pytest.mark.parametrize('case, kept, expect', [
    pytest.param(*c, id=c[0], marks=[] if c[0] in IN_SUITE else [pytest.mark.long]) for c in CASES])
def test_undeclared_effect_in_independent_data(data, case, kept, expect):
    rec = load(data[case], None)
    est, val = rec.split(0.6)
    res = run_ladder(est, val, load_declared(None, 'exponential', rec.theta is not None))
    final = res['steps'][-1].model
    assert final.effects == kept, res['tried']
    for key, (value, tol) in expect.items():
        got = key(final) if callable(key) else final[key]
        assert got == pytest.approx(value, abs=tol), key
    assert not [p.name for p in final.params if p.at_bound(1e-3 * PARAMS[p.name].typical)]
    assert ROUGH.get(case, set()) <= set(getattr(res['steps'][-1].std, 'rough', ()))
    errors = [s.val['x_rms_counts'] for s in res['steps']]
    assert errors[-1] <= errors[0]                  # the ladder never ends worse than the declared model
    if case in NOT_EXPLAINED:       # said so, with the numbers: what is left, beside the rounding's share
        v = res['verdict']
        assert not v['explained'] and v['unexplained_percent'] < NOT_EXPLAINED[case], v
        assert f'{v["unexplained_percent"]:.3g} % of the motion is left' in v['reason']
    else:
        assert res['verdict']['explained'], res['verdict']     # down to what the encoders' rounding leaves


@pytest.mark.long       # a minute; the default run finds a friction rising with speed on EMPS's real drive
def test_a_friction_rising_with_speed_is_found_in_independent_data(tmp_path):
    """The independent simulator's track with a static level below the Coulomb one (mu_s 0.03, mu_c
    0.05, v_s 3 cm/s: a friction that rises with speed), cart alone, 45 s, declared as the paper's falling
    curve: the refitted curve rises, each level within 5 % of the truth, nothing added, nothing on a
    bound, explained down to the encoders' floor. (Which law carries the curve is not asserted: bristles
    stiffer than the encoder resolves are the exponential law.)"""
    spec = dict(rigsim._case('quanser', 'cart', seed=51), rig_overrides={'mu_s': 0.03, 'mu_c': 0.05, 'v_s': 0.03})
    rec = load(rigsim.write_case('rising', tmp_path, data=rigsim.simulate(spec, duration=45.0)), None)
    est, val = rec.split(0.6)
    res = run_ladder(est, val, load_declared(None, 'exponential', False))
    final = res['steps'][-1].model
    fn = rigsim.RIGS['quanser']['M'] * rigsim.RIGS['quanser']['g']        # the pendulum removed
    assert final.effects == (), res['tried']
    assert final['Fc'] == pytest.approx(0.05 * fn, rel=0.05)
    assert final['Fc'] + final['Fs_excess'] == pytest.approx(0.03 * fn, rel=0.05) and final['Fs_excess'] < 0
    assert final['v_s'] == pytest.approx(0.03, rel=0.1) and final['eps'] == pytest.approx(3.0, rel=0.05)
    assert not [p.name for p in final.params if p.at_bound(1e-3 * PARAMS[p.name].typical)]
    assert res['verdict']['explained'], res['verdict']


@pytest.mark.long       # a minute: the friction laws' ladder on a 45 s record
def test_a_cart_without_coulomb_friction_is_answered_by_the_viscous_law(tmp_path):
    """The independent simulator's cart on an air bearing (no Coulomb or static friction: mu_s = mu_c = 0,
    viscous 3 N s/m), 45 s, declared with the paper's Stribeck curve: the refit loses its Coulomb level to
    its bound, which refutes the declared law there; the viscous law is fitted in full and kept, its slope
    within 3 %, nothing on a bound, explained down to the encoders' floor."""
    spec = dict(rigsim._case('quanser', 'cart', seed=52), rig_overrides={'mu_s': 0.0, 'mu_c': 0.0})
    rec = load(rigsim.write_case('air', tmp_path, data=rigsim.simulate(spec, duration=45.0)), None)
    est, val = rec.split(0.6)
    res = run_ladder(est, val, load_declared(None, 'exponential', False))
    final = res['steps'][-1].model
    assert final.law == 'viscous' and final.effects == (), res['tried']
    assert final['eps'] == pytest.approx(3.0, rel=0.03)
    assert not [p.name for p in final.params if p.at_bound(1e-3 * PARAMS[p.name].typical)]
    assert res['verdict']['explained'], res['verdict']


@pytest.mark.long       # two minutes: the friction laws' ladder with the mass free
def test_a_refit_with_a_free_constant_on_a_bound_is_refused(tmp_path):
    """The air-bearing cart of the test above with --free M: the first refit (the declared Stribeck curve
    and M) loses its Coulomb level to its bound; it is refused with that reason, not taken as a step, and
    the rounds go on from the declared values: the viscous law is kept with M fitted beside it, M and the
    slope within 3 %, nothing on a bound."""
    spec = dict(rigsim._case('quanser', 'cart', seed=52), rig_overrides={'mu_s': 0.0, 'mu_c': 0.0})
    rec = load(rigsim.write_case('air', tmp_path, data=rigsim.simulate(spec, duration=45.0)), None)
    est, val = rec.split(0.6)
    declared = load_declared(None, 'exponential', False).freeing(['M'])
    res = run_ladder(est, val, declared)
    first = res['steps'][0].notes
    assert len(first) == 1 and 'refit of the exponential law with M (--free) is refuted: Fc = ' in first[0], first
    assert not res['steps'][0].model.param('M').free        # the declared step holds M as declared
    final = res['steps'][-1].model
    assert final.law == 'viscous' and final.effects == (), res['tried']
    assert final['M'] == pytest.approx(rigsim.RIGS['quanser']['M'], rel=0.03)
    assert final['eps'] == pytest.approx(3.0, rel=0.03)
    assert not [p.name for p in final.params if p.at_bound(1e-3 * PARAMS[p.name].typical)]


def test_a_refit_on_a_bound_has_the_leaner_laws_fitted_in_full(data):
    """The screen of a round (``hypotheses.screen``) on the independent clean cart record: where the refit's
    short fit ends with its Coulomb level on the bound 0, the viscous and Coulomb laws are fitted in full
    even when five hypotheses gained more (outside the ranks); the dynamic law, with more parts, is not;
    with the Coulomb level off its bound they are ranked as any other."""
    from ipfric_core.ident.hypotheses import hypotheses, screen
    from ipfric_core.ident.problem import Problem
    rec = load(data['cart_none'], None, cart_alone=True)
    est, _ = rec.split(0.6)
    pe = Problem(est)
    declared = load_declared(None, 'exponential', False)
    hs = [h for h in hypotheses(pe, declared, declared) if h.kind != 'effect' or not h.levels]
    gains = {'friction': 0.5, 'law': 0.4, 'plant': 0.6, 'effect': 0.7}     # every effect on the declared friction
    for fc, forced in ((0.0, True), (0.3, False)):
        refit = declared.with_free(('Fc', 'Fs_excess', 'eps', 'v_s')).with_values({'Fc': fc})
        short = [(refit if h.kind == 'friction' else h.model, gains[h.kind]) for h in hs]
        notes = dict(zip((h.label for h in hs), screen(hs, short, pe, declared)))
        assert notes['refit'] is None
        assert (notes['law viscous'] is None) == forced and (notes['law coulomb'] is None) == forced, notes
        assert 'not among the 3 best' in notes['law dynamic']


@pytest.mark.slow
@pytest.mark.parametrize('amplitude, period, phase', [(0.05, 0.004, -1.0), (0.03, 0.003, 2.0)])
def test_a_small_cogging_is_fitted_from_the_phase_its_replay_prefers(tmp_path, amplitude, period, phase):
    """A cogging of a few hundredths of a newton and millimetres (far smaller than the cart's Coulomb level
    of 0.34 N) on the independent cart record: the force balance finds its period (``starts.ripple_starts``),
    but the fit of the simulation error from its phase and size ended in another minimum (on the first case:
    39 % of the size, 3.0 counts^2 where the truth leaves 0.55). From the phase, period and size that the
    replay prefers (``starts.phased``) the fit reaches the truth's error, within 0.1 % of its period, 20 % of
    its size and 25 degrees of its phase."""
    from ipfric_core.ident.problem import Problem, fit_model
    from ipfric_core.ident.starts import ripple_starts
    spec = dict(rigsim.CASES['cart_cogging'], size={'amplitude_N': amplitude, 'period_m': period, 'phase_rad': phase})
    rec = load(rigsim.write_case('cart_small_cogging', tmp_path, data=rigsim.simulate(spec)), None, cart_alone=True)
    est, _ = rec.split(0.6)
    pe = Problem(est)
    declared = load_declared(None, 'exponential', False)
    law = ('Fc', 'Fs_excess', 'eps', 'v_s')
    base = declared.with_effect('cogging').with_free(('cogging_sin_N', 'cogging_cos_N', 'cogging_period_m') + law)
    truth = base.with_values({'cogging_period_m': period, 'cogging_sin_N': amplitude * math.cos(phase),
                              'cogging_cos_N': amplitude * math.sin(phase)})
    start = ripple_starts(est, declared, replay=pe)[0]
    fit = fit_model(pe, base.with_values(start), max_nfev=40, prior=declared, errors=False)[0]
    assert pe.cost(fit) <= 1.02 * pe.cost(truth)
    assert fit['cogging_period_m'] == pytest.approx(period, rel=1e-3)
    assert cogging_amplitude(fit) == pytest.approx(amplitude, rel=0.2)
    turn = math.atan2(fit['cogging_cos_N'], fit['cogging_sin_N']) - phase
    assert abs(math.degrees((turn + math.pi) % (2 * math.pi) - math.pi)) < 25


@pytest.mark.parametrize('case', ['cart_none', 'cart_jitter'])
@pytest.mark.parametrize('factor', [1.0, 0.75, 1.3])
def test_force_balance_starts_the_mass_and_friction_from_a_wrong_declaration(data, factor, case):
    """The refit's and the plant corrections' starts from the cart's force balance
    (``starts.balance_starts``) on the independent clean cart record, sampled at 1 ms or at stamps
    jittered by up to 0.3 ms, the paper's cart (its mass as
    Table 1) declared ``factor`` times its mass with the paper's friction: the mass with the mass free
    within 2 %, the friction with it within 10 % (its Coulomb level, the viscous slope); with the mass
    held as declared, alpha read for the same M / alpha within 2 %. (The jittered stamps once gave a mass
    of 0.1 % of the truth: the balance's filter ran over them as if they were even.)"""
    from ipfric_core.ident.starts import balance_starts
    from ipfric_core.physics.params import PlantParams
    truth = rigsim.RIGS['quanser']
    rec = load(data[case], None, cart_alone=True)
    est, _ = rec.split(0.6)
    declared = load_declared(None, 'exponential', False, PlantParams(M=factor * truth['M']))
    st = balance_starts(est, declared)
    assert st['M']['M'] == pytest.approx(truth['M'], rel=0.02)
    fn = truth['M'] * truth['g']
    assert st['M']['Fc'] == pytest.approx(truth['mu_c'] * fn, rel=0.1)
    assert st['M']['eps'] == pytest.approx(truth['eps'], rel=0.1)
    assert st['alpha']['alpha'] == pytest.approx(declared['alpha'] * factor, rel=0.02)
    if factor == 1.0:
        assert st['refit']['Fc'] == pytest.approx(truth['mu_c'] * fn, rel=0.1)


@pytest.mark.parametrize('mean, bias', [(-math.pi + 0.12, 0.12), (0.01, 0.01), (math.pi - 0.04, -0.04)])
def test_the_angle_bias_starts_from_the_nearest_rest(mean, bias):
    """A hanging pendulum's angle, read from upright, averages near +/-pi: the bias starts at its offset from
    there (it started at the mean itself, -3 rad, and ended on its bound of 1 rad)."""
    from ipfric_core.ident.refutations import rest_offset
    assert rest_offset(np.array([mean - 0.05, mean + 0.05])) == pytest.approx(bias, abs=1e-12)


@pytest.mark.slow
def test_drive_play_found_sized_and_exported(data, tmp_path, capsys):
    """A play between the motor side of a two-mass drive and the cart (the encoder on the cart),
    cart alone, 45 s: the ladder keeps the drive play and nothing else, sized as the generator's (the
    tolerances of CASES), the friction as declared, and --export writes every drive parameter."""
    out = tmp_path / 'identified.yaml'
    assert main(['identify', str(data['cart_backlash']), '--out', str(tmp_path / 'r'), '--no-plots', '--json',
                 '--export', str(out)]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r['effects_added'] == ['drive_backlash'], r['effects_tried']
    final = {p['name']: p for p in r['ladder'][-1]['params']}
    assert final['drive_backlash_m']['value'] == pytest.approx(1e-3, abs=9e-5)
    assert final['drive_mass_kg']['value'] == pytest.approx(0.2, abs=0.02)
    # the contact's stiffness and damping: the truth within three standard errors (honest errors: the
    # Jacobian's in the scaled parameters, and a scan of the error where it is rough)
    for name, truth in (('drive_stiffness_N_per_m', 2e5), ('drive_damping_Ns_per_m', 50.0), ('drive_backlash_m', 1e-3),
                        ('drive_mass_kg', 0.2)):
        assert abs(final[name]['value'] - truth) <= 3 * final[name]['std'], (name, final[name])
        assert final[name]['std'] < abs(truth), (name, final[name])     # and not merely unbounded
    assert final['Fc']['value'] == pytest.approx(0.3425, abs=0.02)
    assert not any(p['at_bound'] for p in final.values())
    errors = [s['validation']['x_rms_counts'] for s in r['ladder']]
    assert errors[-1] < 0.1 * errors[0]          # 30 counts of coasting through the play explained
    # the report names no figure it did not draw, and no cogging period without a cogging
    assert not r['figures'] and 'Figures:' not in (tmp_path / 'r' / 'report.md').read_text()
    assert 'cogging_period_m' not in r['identified']['plant_truth']
    truth = load_scenario(out).truth
    assert truth.drive_backlash_m == pytest.approx(final['drive_backlash_m']['value'])
    assert truth.drive_mass_kg == pytest.approx(final['drive_mass_kg']['value'])
    assert truth.drive_stiffness_N_per_m == pytest.approx(final['drive_stiffness_N_per_m']['value'])
    assert truth.drive_damping_Ns_per_m == pytest.approx(final['drive_damping_Ns_per_m']['value'])


@pytest.mark.long     # the default run's campaign cases: other rigs, with overruns (test_campaign_fixed.py)
def test_other_rig_with_overruns_and_5ms_sampling_stays_plausible(data, tmp_path, capsys):
    """ip02: lighter cart, other motor; its plant file declares only the plant (the paper's
    friction is the hypothesis). The refit friction is that rig's, nothing is added, the
    overruns are counted and left out."""
    plant = tmp_path / 'ip02.yaml'
    rig = rigsim.RIGS['ip02']
    plant.write_text('plant: {' + ', '.join(f'{k}: {rig[k]}' for k in ('M', 'm', 'l', 'g', 'alpha', 'beta')) + '}\n')
    assert main(['identify', str(data['ip02_cart']), '--plant', str(plant), '--out', str(tmp_path / 'cart'),
                 '--json']) == 0
    r = json.loads(capsys.readouterr().out)
    assert any('sample overruns' in n for n in r['data']['notes'])
    assert r['data']['sample_period_s'] == pytest.approx(0.005, rel=0.01)
    assert r['effects_added'] == []
    refit = {p['name']: p for p in r['ladder'][1]['params']}
    fn = rig['M'] * rig['g']
    # that rig's friction (window starts beside an overrun take their velocity from fresh readings
    # only: with the stale ones the Coulomb level came out 40 % low and 78 counts were left)
    assert refit['Fc']['value'] == pytest.approx(rig['mu_c'] * fn, rel=0.05)
    assert refit['Fc']['value'] + refit['Fs_excess']['value'] == pytest.approx(rig['mu_s'] * fn, rel=0.05)
    assert refit['eps']['value'] == pytest.approx(rig['eps'], rel=0.05)
    assert refit['M']['value'] == rig['M'] and not refit['M']['fitted']
    assert not any(p['at_bound'] for p in r['ladder'][-1]['params'])
    assert r['ladder'][1]['validation']['x_rms_counts'] < 5.0      # 0.5 % of the motion
    for name in ('report.md', 'ladder.png', 'windows.png'):
        assert (tmp_path / 'cart' / name).stat().st_size > 0
    assert main(['identify', str(data['ip02_loop_hanging']), '--plant', str(plant), '--out',
                 str(tmp_path / 'loop'), '--json', '--no-plots']) == 0
    r = json.loads(capsys.readouterr().out)
    assert any('hanging' in n for n in r['data']['notes'])
    # the loop moves the cart at 1-3 cm/s, below the Stribeck velocity (8 cm/s): the refit determines
    # the friction at those speeds and the static level, not the law's parameters one by one; the report
    # says so, prints the correlated pair, and the errors cover the truth
    refit = r['ladder'][1]
    fn = (rig['M'] + rig['m']) * rig['g']
    fc, fs, eps, vs = rig['mu_c'] * fn, rig['mu_s'] * fn, rig['eps'], rig['v_s']
    assert r['data']['moving_speeds_mps']['p95'] < vs
    assert any('below the Stribeck velocity' in n for n in refit['notes'])
    pair = next(c for c in refit['correlations'] if {c['a'], c['b']} == {'Fc', 'Fs_excess'})
    assert abs(pair['r']) > 0.9 and pair['combination'] == pytest.approx(fs, abs=3 * pair['combination_std'])
    for c in refit['friction_at_speeds']:
        v = c['v']
        truth = fc + (fs - fc) * math.exp(-(v / vs) ** 2) + eps * v
        # within three standard errors and what the two integrators' stick-slip and the overruns' timing
        # leave beside them (0.2 % of the force: a 4-sigma miss of 1 mN at 34 mm/s was seen)
        assert c['force'] == pytest.approx(truth, abs=3 * c['std'] + 2e-3 * truth), c
    p = {q['name']: q for q in refit['params']}
    # the Coulomb level alone is known to a third only (it trades with the Stribeck excess along the pair);
    # its standard error does not cover that valley (see docs/identification.md, Known limits)
    assert p['Fc']['value'] == pytest.approx(fc, rel=0.35)
    assert 'sensor_bias' not in r['effects_added']
    assert not any(p['at_bound'] for p in r['ladder'][-1]['params'])
    dz = [t for t in r['effects_tried'] if t['effect'] == 'deadzone']
    assert not dz or not dz[0]['kept'] or dz[0]['values']['deadzone_V'] < 0.5
