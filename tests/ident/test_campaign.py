"""The randomised independent campaign (tests/independent/campaign.py, scored by
bench/ident_campaign.py): the generator is reproducible (the same (seed, index) gives the same bytes) and
every drawn case is physically sane; the true drive replays the generator's; the scorer's rules on
hand-made answers; resume and merge of a campaign run in parts. Its fixed cases identified as the campaign
runs them: test_campaign_fixed.py; the drawn cases the ladder once answered wrong: test_campaign_cases.py.
"""
import hashlib
import json
import math

import numpy as np
import pytest
from independent import campaign

from bench import ident_campaign as scorer

SEED = 2026


def test_drawn_cases_are_physically_sane():
    n = 0
    none = 0
    for seed in (0, 1):
        for i in range(250):
            s = campaign.draw_case(seed, i)
            r = s['rig']
            assert 0.2 <= r['M'] <= 2.0 and 0.0 < r['m'] < r['M'] and 0.05 < r['l'] < 0.5
            assert 0.5 <= r['alpha'] <= 3.0 and 1.0 <= r['beta'] <= 12.0
            assert 0.05 <= r['Fc'] <= 2.0 and r['Fs'] > r['Fc'] and r['eps'] > 0 and r['v_s'] > 0
            assert 1e-5 <= r['x_res'] <= 1e-4 and 2 * math.pi / 4096 <= r['theta_res'] <= 2 * math.pi / 1024
            assert 1e-3 <= s['Ts'] <= 1e-2 and 30.0 <= s['duration'] <= 120.0
            assert len(s['effects']) <= 2
            assert set(s['effects']) <= set(campaign.LIBRARY) | set(campaign.OUTSIDE)
            if 'sensor_bias' in s['effects']:
                assert s['pendulum_attached']
            if 'plant_error' in s:
                assert 0.1 <= abs(s['plant_error']['factor'] - 1) <= 0.4
            none += not s['effects']
            n += 1
    assert 0.15 < none / n < 0.35


@pytest.fixture(scope='module')
def short_cases(tmp_path_factory):
    """Three short cases (cart alone with a zeros theta column, hanging, closed loop) written twice."""
    dirs = [tmp_path_factory.mktemp(f'campaign{k}') for k in range(2)]
    for d in dirs:
        campaign.generate(d, 0, SEED, indices=[2, 89, 14], duration=12.0)
    return dirs


def test_generator_is_reproducible(short_cases):
    a, b = short_cases
    for case in ('case0002', 'case0089', 'case0014'):
        for name in ('data.csv', 'plant.yaml', 'truth.json'):
            assert (a / case / name).read_bytes() == (b / case / name).read_bytes(), (case, name)


def test_written_cases_are_on_the_encoder_grid(short_cases):
    for case in ('case0002', 'case0089', 'case0014'):
        d = short_cases[0] / case
        truth = json.loads((d / 'truth.json').read_text())
        header = (d / 'data.csv').read_text().splitlines()[0].split(',')
        assert header == truth['columns']
        data = np.loadtxt(d / 'data.csv', delimiter=',', skiprows=1)
        assert np.isfinite(data).all()
        t, x = data[:, 0], data[:, 1]
        assert np.all(np.diff(t) > 0)
        counts = x / truth['encoder']['x_count_m']
        assert np.abs(counts - np.round(counts)).max() < 1e-6
        if 'theta' in header:
            th = data[:, 3] / truth['encoder']['theta_count_rad']
            assert np.abs(th - np.round(th)).max() < 1e-6
            if truth['theta_column'] == 'zeros':
                assert not data[:, 3].any()
        c = truth['constants']
        assert c['M'] > 0 and c['m'] > 0 and c['l'] > 0 and c['alpha'] > 0 and c['beta'] > 0
        assert truth['friction']['Fc'] > 0
        assert truth['replay_self_error_counts_rms'] < 0.05     # the replay reproduces the run
        plant = (d / 'plant.yaml').read_text()
        assert 'plant: {M: ' in plant
    assert json.loads((short_cases[0] / 'case0002' / 'truth.json').read_text())['theta_column'] == 'zeros'


def _truth(effects=(), plant_error=None):
    return {'effects': {k: {'library': k in campaign.LIBRARY, 'contribution_counts_rms': v} for k, v in effects},
            'plant_error': plant_error}


@pytest.mark.parametrize('effects, added, verdict, expected, outcome', [
    ((), [], None, 'none', 'correct'),
    ((), ['offset'], None, 'none', 'false_positive'),
    ((), ['stribeck'], None, 'none', 'correct'),                       # friction-law parts are no effects
    ((('deadzone', 30.0),), ['deadzone'], None, 'deadzone', 'correct'),
    ((('deadzone', 30.0),), ['offset'], None, 'deadzone', 'wrong'),
    ((('deadzone', 30.0),), [], None, 'deadzone', 'missed'),
    ((('deadzone', 0.5),), [], None, 'none', 'correct'),
    ((('deadzone', 0.5),), ['deadzone'], None, 'none', 'acceptable'),
    ((('deadzone', 0.5),), ['cogging'], None, 'none', 'wrong'),
    ((('spring', 40.0),), [], {'explained': False}, 'not_explained', 'correct'),
    ((('spring', 40.0),), ['offset'], {'explained': False}, 'not_explained', 'wrong'),
    ((('spring', 40.0),), [], {'explained': True}, 'not_explained', 'missed'),
    ((('cogging', 9.0), ('delay', 5.0)), ['cogging'], None, 'cogging+delay', 'partial'),
    ((('asymmetry', 9.0),), ['offset'], None, 'asymmetry', 'alike'),     # alike while the cart slides
    ((('asymmetry', 9.0),), ['cogging'], None, 'asymmetry', 'wrong'),
    ((('delay', 9.0),), ['lag'], None, 'delay', 'alike'),               # a lag of the same size acts alike
    ((), ['lag'], None, 'none', 'false_positive'),
])
def test_scorer_rules(effects, added, verdict, expected, outcome):
    truth = _truth(effects)
    exp = scorer.expected_answer(truth, 2.0)
    assert exp['label'] == expected
    result = {'effects_added': added, **({'verdict': verdict} if verdict is not None else {})}
    assert scorer.outcome(exp, scorer.predicted_answer(result)) == outcome
    assert scorer.outcome(exp, scorer.predicted_answer(None)) == 'error'


def test_a_wrong_declared_constant_expects_its_correction_or_not_explained():
    truth = _truth((), {'name': 'alpha', 'factor': 0.7, 'contribution_counts_rms': 50.0})
    exp = scorer.expected_answer(truth, 2.0)
    assert exp['label'] == 'alpha corrected'          # the ladder corrects M, alpha and beta
    corrected = {'effects_added': [], 'constants_corrected': ['alpha'], 'verdict': {'explained': True}}
    assert scorer.outcome(exp, scorer.predicted_answer(corrected)) == 'correct'
    refit = {'effects_added': [], 'constants_corrected': [], 'verdict': {'explained': True}}
    assert scorer.outcome(exp, scorer.predicted_answer(refit)) == 'missed'
    emf = _truth((('deadzone', 30.0),), {'name': 'beta', 'factor': 0.7, 'contribution_counts_rms': 900.0})
    assert scorer.expected_answer(emf, 2.0)['label'] == 'deadzone'   # eps takes a wrong beta over exactly
    viscous = {'effects_added': ['deadzone'], 'constants_corrected': ['beta'], 'verdict': {'explained': True}}
    assert scorer.outcome(scorer.expected_answer(emf, 2.0), scorer.predicted_answer(viscous)) == 'correct'
    as_m = {'effects_added': [], 'constants_corrected': ['M'], 'verdict': {'explained': True}}
    assert scorer.outcome(exp, scorer.predicted_answer(as_m)) == 'wrong'      # a pendulum on the cart tells them
    cart = dict(truth, pendulum_attached=False)         # the cart alone fixes M / alpha only
    assert scorer.outcome(scorer.expected_answer(cart, 2.0), scorer.predicted_answer(as_m)) == 'alike'
    pendulum = _truth((), {'name': 'l', 'factor': 1.3, 'contribution_counts_rms': 50.0})
    assert scorer.expected_answer(pendulum, 2.0)['label'] == 'not_explained'   # no correction for m, l
    both = {'effects_added': [], 'constants_corrected': ['M', 'alpha'], 'verdict': {'explained': False}}
    assert scorer.outcome(scorer.expected_answer(pendulum, 2.0), scorer.predicted_answer(both)) == 'wrong'
    mass = _truth((), {'name': 'm', 'factor': 1.3, 'contribution_counts_rms': 50.0})
    exp_m = scorer.expected_answer(mass, 2.0)
    assert exp_m['label'] == 'not_explained'
    # the cart's equation times 1.3 is the same model: M and alpha corrected together, not one of them
    assert scorer.outcome(exp_m, scorer.predicted_answer(both)) == 'alike'
    assert scorer.outcome(exp_m, scorer.predicted_answer(as_m)) == 'wrong'
    spring = _truth((('spring', 40.0),), {'name': 'm', 'factor': 1.3, 'contribution_counts_rms': 50.0})
    assert scorer.outcome(scorer.expected_answer(spring, 2.0), scorer.predicted_answer(both)) == 'wrong'
    assert scorer.detection_limit([(1.0, False), (3.0, True), (5.0, True), (9.0, True)]) == 3.0
    assert scorer.detection_limit([(1.0, True), (3.0, False)]) is None


def test_a_drive_whose_play_is_not_seen_expects_the_mass_of_its_motor_side():
    def drive(total, play):
        truth = _truth((('drive_backlash', total),))
        truth['effects']['drive_backlash'].update(play_contribution_counts_rms=play, motor_mass_kg=0.12)
        return truth
    mass = {'effects_added': [], 'constants_corrected': ['M'], 'verdict': {'explained': True}}
    play = {'effects_added': ['drive_backlash'], 'constants_corrected': [], 'verdict': {'explained': True}}
    hidden = scorer.expected_answer(drive(260.0, 1.5), 2.0)
    assert hidden['label'] == 'M corrected'           # the motor side moves with the cart: a heavier cart
    assert scorer.outcome(hidden, scorer.predicted_answer(mass)) == 'correct'
    seen = scorer.expected_answer(drive(260.0, 3.8), 2.0)
    assert seen['label'] == 'drive_backlash'          # the play itself reaches the threshold
    assert scorer.components(drive(260.0, 3.8))[0]['counts'] == 3.8     # its size: the play's own part
    assert scorer.outcome(seen, scorer.predicted_answer(play)) == 'correct'
    assert scorer.outcome(seen, scorer.predicted_answer(mass)) == 'wrong'
    tiny = drive(260.0, 10.6)                           # its contact rings, but its play is 0.4 count
    tiny.update(encoder={'x_count_m': 2.5e-5})
    tiny['effects']['drive_backlash']['gap_m'] = 1e-5
    assert scorer.expected_answer(tiny, 2.0)['label'] == 'M corrected'   # as the ladder refutes it
    # named with its play closed (a compliant contact without play), the drive itself: alike
    closed = dict(play, ladder=[{'params': [{'name': 'drive_backlash_m', 'value': 1e-9, 'fitted': False}]}])
    assert scorer.predicted_answer(closed)['added'] == [scorer.CLOSED_DRIVE]
    assert scorer.outcome(scorer.expected_answer(tiny, 2.0), scorer.predicted_answer(closed)) == 'alike'
    assert scorer.outcome(scorer.expected_answer(tiny, 2.0), scorer.predicted_answer(play)) == 'wrong'
    tiny['effects']['drive_backlash']['gap_m'] = 7.5e-5                   # three counts: a play to name
    assert scorer.expected_answer(tiny, 2.0)['label'] == 'drive_backlash'
    assert scorer.outcome(scorer.expected_answer(tiny, 2.0), scorer.predicted_answer(closed)) == 'wrong'
    assert scorer.outcome(hidden, scorer.predicted_answer(closed)) == 'wrong'   # its play unseen for its size only
    # a play that does less than the threshold beyond the same drive with its play closed: a compliant contact
    tiny['effects']['drive_backlash']['closed_contribution_counts_rms'] = 1.2
    contact = scorer.expected_answer(tiny, 2.0)
    assert contact['label'] == scorer.CLOSED_DRIVE
    assert scorer.outcome(contact, scorer.predicted_answer(closed)) == 'correct'
    assert scorer.outcome(contact, scorer.predicted_answer(play)) == 'alike'       # its play named: the same drive
    assert scorer.outcome(contact, scorer.predicted_answer(mass)) == 'wrong'       # its ringing is left


def test_an_answer_counted_alike_counts_its_effect_named():
    """The per-effect tally (detection limits) reads an answer as the outcome does: a drive whose play the
    encoder cannot show, answered with its play closed, names the mass correction it is scored as."""
    truth = _truth((('drive_backlash', 260.0),))
    truth['effects']['drive_backlash'].update(play_contribution_counts_rms=10.6, motor_mass_kg=0.12, gap_m=1e-5)
    truth.update(encoder={'x_count_m': 2.5e-5}, index=0, experiment='cart', theta_column='none',
                 sample_period_s=1e-3, duration_s=30.0, timing={'kind': 'regular'})
    exp = scorer.expected_answer(truth, 2.0)
    assert exp['label'] == 'M corrected' and exp['alike'] == {scorer.CLOSED_DRIVE: 'M corrected'}
    closed = {'effects_added': ['drive_backlash'], 'verdict': {'explained': True},
              'ladder': [{'step': '+ drive_backlash', 'validation': {'x_rms_counts': 1.0},
                          'params': [{'name': 'drive_backlash_m', 'value': 1e-9, 'fitted': False}]}]}
    offset = {'effects_added': ['offset'], 'verdict': {'explained': True}}
    rows = [scorer.score_case(dict(truth, case=f'case{i}'), {'result': result, 'wall_s': 1.0}, 2.0, 1.0)
            for i, result in enumerate((closed, offset))]
    assert [r['outcome'] for r in rows] == ['alike', 'wrong']
    points = scorer.summarize(rows, 2.0, {})['per_effect']['M corrected']['points']
    assert [p['named'] for p in points] == [True, False]


def test_standard_errors_are_checked_against_the_truth_on_clean_cases():
    truth = {'friction': {'Fc': 0.5, 'Fs_excess': 0.2, 'eps': 3.0, 'v_s': 0.1}}

    def result(values, stds, law=('Fc', 'Fs_excess', 'eps', 'v_s')):
        params = [{'name': 'M', 'value': 1.0, 'std': None, 'fitted': False}]
        params += [{'name': n, 'value': values[n], 'std': stds.get(n), 'fitted': n in stds} for n in law]
        return {'ladder': [{'params': params}]}
    z = scorer.friction_z(truth, result({'Fc': 0.53, 'Fs_excess': 0.2, 'eps': 2.0, 'v_s': 0.1},
                                        {'Fc': 0.01, 'eps': 0.25, 'v_s': math.inf}))
    assert z == pytest.approx({'Fc': 3.0, 'eps': -4.0})        # Fs_excess held, v_s without an error
    # another law's levels mean other things: not checked
    assert scorer.friction_z(truth, result(truth['friction'], {'Fc': 0.1}, ('Fc', 'Fs_excess', 'eps'))) == {}
    assert scorer.friction_z(truth, None) == {}
    cases = [{'components': [], 'experiment': 'loop', 'friction_z': {'Fc': 3.0, 'eps': -1.0}},
             {'components': [], 'experiment': 'cart', 'friction_z': {'Fc': 0.5, 'eps': 0.3}},
             {'components': [{'name': 'offset'}], 'experiment': 'cart', 'friction_z': {'Fc': 9.0}},   # not clean
             {'components': [], 'experiment': 'cart', 'friction_z': {}}]
    cov = scorer.coverage(cases)
    assert set(cov) == {'all', 'cart', 'loop'}
    assert cov['loop'] == {'n': 2, 'median_abs_z': 2.0, 'within': 0.5}
    assert cov['cart']['within'] == 1.0 and cov['all']['n'] == 4


def test_a_deadzone_counts_by_what_a_friction_level_cannot_take_over():
    def dz(total, beyond):
        truth = _truth((('deadzone', total),))
        truth['effects']['deadzone']['beyond_friction_counts_rms'] = beyond
        return truth
    none = {'effects_added': [], 'constants_corrected': [], 'verdict': {'explained': True}}
    named = {'effects_added': ['deadzone'], 'constants_corrected': [], 'verdict': {'explained': True}}
    small = scorer.expected_answer(dz(8.0, 1.6), 2.0)
    assert small['label'] == 'none'               # a Coulomb level higher by alpha dz does the rest
    assert scorer.outcome(small, scorer.predicted_answer(none)) == 'correct'
    assert scorer.outcome(small, scorer.predicted_answer(named)) == 'acceptable'
    large = scorer.expected_answer(dz(747.0, 230.0), 2.0)
    assert large['label'] == 'deadzone'
    assert scorer.outcome(large, scorer.predicted_answer(none)) == 'missed'
    loop = scorer.expected_answer(dz(0.77, 3.3), 2.0)
    assert loop['label'] == 'none'                # the model without it is nearer than the shifted level
    assert scorer.components(dz(31.5, 49.0))[0]['counts'] == 31.5


def test_an_offset_names_a_springs_mean_pull_and_is_no_wrong_name():
    def spring(whole, pull=0.0034, part=4.4, library=None):
        effects = {'spring': {'library': False, 'contribution_counts_rms': whole, 'mean_pull_N': pull,
                              'preload_N': 0.00345, 'k_N_per_m': 0.07, 'mean_pull_contribution_counts_rms': part}}
        effects.update({k: {'library': True, 'contribution_counts_rms': v} for k, v in (library or {}).items()})
        return {'effects': effects, 'plant_error': {'name': 'alpha', 'factor': 0.69, 'contribution_counts_rms': 361.0}}

    def answer(offset, corrected=('alpha',), effects=('offset',)):
        return {'effects_added': list(effects), 'constants_corrected': list(corrected), 'verdict': {'explained': False},
                'ladder': [{'params': [{'name': 'offset_N', 'value': offset, 'fitted': True}]}]}
    exp = scorer.expected_answer(spring(15.5), 2.0)
    assert exp['label'] == 'alpha corrected' and exp['pull_N'] == 0.0034      # naming the pull is not required
    assert scorer.outcome(exp, scorer.predicted_answer(answer(0.00338))) == 'correct'      # seed 2027, case 38
    assert scorer.outcome(exp, scorer.predicted_answer(answer(-0.00338))) == 'partial'     # not the pull
    assert scorer.outcome(exp, scorer.predicted_answer(answer(0.0075))) == 'partial'       # beyond a factor 2
    assert scorer.outcome(exp, scorer.predicted_answer(answer(0.0015))) == 'partial'       # below half of it
    # an offset the library expects beside the spring is that offset, not the pull set aside
    both = scorer.expected_answer(spring(15.5, library={'offset': 40.0}), 2.0)
    assert scorer.outcome(both, scorer.predicted_answer(answer(0.0034))) == 'correct'
    assert scorer.outcome(both, scorer.predicted_answer(answer(0.0034, effects=()))) == 'partial'
    alone = dict(spring(166.0), plant_error=None)
    exp = scorer.expected_answer(alone, 2.0)
    assert exp['label'] == 'not_explained'
    assert scorer.outcome(exp, scorer.predicted_answer(answer(0.004, ()))) == 'correct'
    assert scorer.outcome(exp, scorer.predicted_answer(answer(-0.004, ()))) == 'wrong'
    unseen = dict(spring(166.0, part=1.9), plant_error=None)
    assert scorer.outcome(scorer.expected_answer(unseen, 2.0), scorer.predicted_answer(answer(0.004, ()))) == 'wrong'


def test_one_correction_that_replays_what_is_outside_the_library_is_another_name_of_it():
    """Seed 2027's case 123: a pendulum mass declared 0.71 times its value beside a 3.5-count spring in a balancing
    loop; one correction of alpha (or of M) replays both within 1.1 counts, and the identification answered
    alpha corrected, explained to the floor."""
    truth = _truth((('spring', 3.5),), {'name': 'm', 'factor': 0.71, 'contribution_counts_rms': 11.9,
                                       'one_correction_counts_rms': {'alpha corrected': 1.09, 'M corrected': 1.16}})
    exp = scorer.expected_answer(truth, 2.0)
    assert exp['label'] == 'not_explained' and exp['single'] == ['M corrected', 'alpha corrected']

    def answer(*corrected, explained=True):
        return {'effects_added': [], 'constants_corrected': list(corrected), 'verdict': {'explained': explained}}
    assert scorer.outcome(exp, scorer.predicted_answer(answer('alpha'))) == 'alike'
    assert scorer.outcome(exp, scorer.predicted_answer(answer('M'))) == 'alike'
    assert scorer.outcome(exp, scorer.predicted_answer(answer('M', 'alpha'))) == 'alike'   # holds either
    truth['plant_error']['one_correction_counts_rms']['M corrected'] = 5.0
    assert scorer.outcome(scorer.expected_answer(truth, 2.0), scorer.predicted_answer(answer('M'))) == 'wrong'
    assert scorer.outcome(scorer.expected_answer(truth, 2.0), scorer.predicted_answer(answer('M', 'alpha'))) == 'alike'
    assert scorer.outcome(exp, scorer.predicted_answer(answer(explained=False))) == 'correct'
    assert scorer.outcome(exp, scorer.predicted_answer(answer())) == 'missed'
    # one that leaves more than the threshold is a wrong name (case 55: 71 counts left by alpha alone)
    truth['plant_error']['one_correction_counts_rms'] = {'alpha corrected': 71.2, 'M corrected': 86.6}
    assert scorer.outcome(scorer.expected_answer(truth, 2.0), scorer.predicted_answer(answer('alpha'))) == 'wrong'


def test_the_generator_measures_what_one_correction_leaves_of_a_wrong_pendulum_mass():
    """Seed 2027, 20 s: case 123 (m declared 0.71 times, a spring beside it) is replayed by one correction within
    the threshold; case 55 (m declared 0.80 times, the pendulum hanging) needs both."""
    for index, least, most in ((123, 0.0, 2.0), (55, 20.0, 200.0)):
        _, truth = campaign.make_case(2027, index, duration=20.0)
        left = truth['plant_error']['one_correction_counts_rms']
        assert set(left) == {'alpha corrected', 'M corrected'}
        for name, counts in left.items():
            assert least < counts < most, (index, name, counts)


def test_the_generator_parts_a_spring_into_its_pull_along_the_track_and_its_mean_pull():
    """Seed 2027, case 38, 20 s: a cable of 0.07 N/m with a preload of 0.0035 N on a cart whose friction is
    0.23 N; over its first 20 s the cart stands 39 mm left of the centre on average, so the cable's mean pull
    is 0.0062 N (over the whole 54.5 s it stands 8 mm right of it: 0.0029 N)."""
    _, truth = campaign.make_case(2027, 38, duration=20.0)
    q = truth['effects']['spring']
    assert q['preload_N'] == pytest.approx(0.00345, rel=0.01)
    assert q['mean_pull_N'] == pytest.approx(q['preload_N'] - q['k_N_per_m'] * truth['motion']['mean_x_m'])
    assert truth['motion']['mean_x_m'] == pytest.approx(-0.039, abs=0.002)
    assert q['mean_pull_N'] == pytest.approx(0.0062, abs=0.0002)
    assert 0.1 < q['mean_pull_contribution_counts_rms'] < q['contribution_counts_rms']


@pytest.mark.parametrize('seed, index, play_max', [(2026, 42, 6.0)])
def test_the_generator_parts_a_drive_into_its_play_and_its_mass(seed, index, play_max):
    """Case 42 of seed 2026: a 0.21 mm play with a motor side of a quarter of the cart's mass; the
    drive changes the motion by 264 counts, nearly all of it the motor side's mass."""
    _, truth = campaign.make_case(seed, index, duration=20.0)
    q = truth['effects']['drive_backlash']
    assert 0.5 < q['play_contribution_counts_rms'] < play_max < 10 * play_max < q['contribution_counts_rms']



def test_the_true_drive_replays_the_generators_drive(tmp_path):
    """Seed 2027, case 74, 30 s: a cart at 1 kHz with overruns, a 0.04 mm play (2.3 counts) against a 22 kN/m
    contact. The identification's drive with the generator's true values replays the record to 2.13 counts
    RMS on validation (2.95 with the motor side's start state estimated along the measured cart rather than
    from the model's lead); with the contact at the edge of the play in each window's start, not compressed
    by the force it carries (as much as the play itself at 1 N), it left 37.8."""
    campaign.generate(tmp_path, 0, 2027, indices=[74], duration=30.0)
    d = tmp_path / campaign.case_name(74)
    truth = json.loads((d / 'truth.json').read_text())
    assert truth['effects']['drive_backlash']['gap_m'] < 2.5 * truth['encoder']['x_count_m']
    assert scorer.oracle(d, truth)['x_rms_counts'] < 5.0


def test_the_true_drive_replays_a_balancing_loop(tmp_path):
    """Seed 2027, case 170, 30 s: an LQR balancing loop at 1 kHz on a drive with a 0.24 mm play. The motor
    side's state and the cart's rate at each window's start, taken from the model's own lead over the second
    before, let the true drive replay the record to 0.65 counts RMS on validation; estimated along the measured
    cart (the open-loop :func:`~ipfric_core.ident.shooting.drive_states`) they left 26.4, and a heavier cart
    without play explained the record as well as the true drive."""
    campaign.generate(tmp_path, 0, 2027, indices=[170], duration=30.0)
    d = tmp_path / campaign.case_name(170)
    truth = json.loads((d / 'truth.json').read_text())
    assert truth['experiment'] == 'loop' and truth['effects']['drive_backlash']['gap_m'] > 1e-4
    assert scorer.oracle(d, truth)['x_rms_counts'] < 2.0


def test_resume_keeps_the_cases_of_this_code_and_refuses_another_code_or_draw(tmp_path, monkeypatch):
    """--resume scores a case this code already identified without running it again; cases of another
    commit, or a directory of another seed, are refused (one summary is one code's answers to one draw)."""
    out = tmp_path / 'camp'
    campaign.generate(out / 'cases', 0, SEED, indices=[2], duration=12.0)
    ident = out / 'cases' / 'case0002' / 'ident'
    ident.mkdir()
    (ident / 'meta.json').write_text(json.dumps({'rc': 2, 'wall_s': 1.5, 'stderr_tail': ['refused'],
                                                  'command': './ipfric identify ...', 'oracle_counts': None,
                                                  'commit': 'abc1234'}))
    monkeypatch.setattr(scorer, 'code_commit', lambda: 'abc1234')
    s = scorer.run_campaign(out, 0, SEED, indices=[2], resume=True, with_oracle=False)
    assert s['outcomes'] == {'error': 1}
    assert s['meta']['resumed_cases'] == 1 and s['meta']['commit'] == 'abc1234'
    # the row names the draw it scored (a balancing loop's bytes differ between machines), the meta the machine
    data = (out / 'cases' / 'case0002' / 'data.csv').read_bytes()
    assert s['cases'][0]['data_sha256'] == hashlib.sha256(data).hexdigest()
    assert s['meta']['machine']['arch'] and s['meta']['machine']['numpy'] == np.__version__
    assert not (ident / 'stderr.txt').exists()          # identify_case never ran
    assert 'code abc1234' in (out / 'summary.md').read_text()
    (out / 'summary.json').unlink()                     # stopped before its summary: rescored from the cases
    scorer.rescore(out)
    assert f'seed {SEED}, code abc1234' in (out / 'summary.md').read_text()
    killed = out / 'cases' / 'case0007' / 'ident'      # stopped by a signal: not done, identified again
    killed.mkdir(parents=True)
    (killed / 'meta.json').write_text(json.dumps({'rc': -15, 'commit': 'abc1234'}))
    assert scorer.done_cases(out, SEED, 'abc1234') == {'case0002'}
    monkeypatch.setattr(scorer, 'code_commit', lambda: 'def5678')
    with pytest.raises(SystemExit, match='case0002 was identified by code abc1234, this tree is def5678'):
        scorer.run_campaign(out, 0, SEED, indices=[2], resume=True, with_oracle=False)
    with pytest.raises(SystemExit, match=f'holds the draw of seed {SEED}, not {SEED + 1}'):
        scorer.run_campaign(out, 0, SEED + 1, indices=[2], resume=True, with_oracle=False)


def test_merge_joins_parts_of_one_campaign_and_refuses_others(tmp_path, monkeypatch):
    """--merge writes one summary of a campaign run in parts: a directory's cases scored again and a
    summary.json's scored cases (a part whose case files are gone); a case in two parts, parts of two
    codes or scored at another threshold are refused. --newest joins parts of several codes, each case's row
    from the newest code."""
    monkeypatch.setattr(scorer, 'code_commit', lambda: 'abc1234')
    for part, index in (('a', 2), ('b', 3)):
        out = tmp_path / part
        campaign.generate(out / 'cases', 0, SEED, indices=[index], duration=12.0)
        ident = out / 'cases' / campaign.case_name(index) / 'ident'
        ident.mkdir()
        (ident / 'meta.json').write_text(json.dumps({'rc': 2, 'wall_s': 1.5, 'stderr_tail': ['refused'],
                                                      'command': './ipfric identify ...', 'oracle_counts': None,
                                                      'commit': 'abc1234'}))
        scorer.run_campaign(out, 0, SEED, indices=[index], resume=True, with_oracle=False)
    s = scorer.merge(tmp_path / 'all', [tmp_path / 'a', tmp_path / 'b' / 'summary.json'])
    assert [c['case'] for c in s['cases']] == ['case0002', 'case0003']
    assert s['meta']['seed'] == SEED and s['meta']['commit'] == 'abc1234' and s['n_cases'] == 2
    assert s['meta']['machines'] == [scorer.machine()]        # both parts ran here
    assert '2 cases' in (tmp_path / 'all' / 'summary.md').read_text()
    # a campaign kept as that summary goes on with the cases it does not hold
    assert scorer.not_held(range(5), [tmp_path / 'all' / 'summary.json'], SEED) == [0, 1, 4]
    with pytest.raises(SystemExit, match=f'holds the draw of seed {SEED}, not {SEED + 1}'):
        scorer.not_held(range(5), [tmp_path / 'all' / 'summary.json'], SEED + 1)
    with pytest.raises(SystemExit, match='holds the answers of code abc1234, this tree is def5678'):
        monkeypatch.setattr(scorer, 'code_commit', lambda: 'def5678')
        scorer.not_held(range(5), [tmp_path / 'all' / 'summary.json'], SEED)
    monkeypatch.setattr(scorer, 'code_commit', lambda: 'abc1234')
    with pytest.raises(SystemExit, match='case0002 is in two parts'):
        scorer.merge(tmp_path / 'x', [tmp_path / 'a', tmp_path / 'a' / 'summary.json'])
    with pytest.raises(SystemExit, match='scored at 2.0 counts, not 3.0'):
        scorer.merge(tmp_path / 'x', [tmp_path / 'b' / 'summary.json'], threshold=3.0)
    other = json.loads((tmp_path / 'b' / 'summary.json').read_text())
    other['meta']['commit'] = 'def5678'
    (tmp_path / 'b' / 'summary.json').write_text(json.dumps(other))
    with pytest.raises(SystemExit, match="codes \\['abc1234', 'def5678'\\]"):
        scorer.merge(tmp_path / 'x', [tmp_path / 'a', tmp_path / 'b' / 'summary.json'])
    # each case's newest answer over parts of several codes: the parts in the order of their codes' commits
    older = json.loads((tmp_path / 'all' / 'summary.json').read_text())
    older['meta']['commit'] = 'abc1234'
    newer = dict(other, cases=[dict(c, outcome='correct', predicted='none') for c in other['cases']])
    (tmp_path / 'old.json').write_text(json.dumps(older))
    (tmp_path / 'new.json').write_text(json.dumps(newer))
    monkeypatch.setattr(scorer, 'commit_time', {'abc1234': 100, 'def5678': 200}.get)
    for order in ([tmp_path / 'new.json', tmp_path / 'old.json'], [tmp_path / 'old.json', tmp_path / 'new.json']):
        s = scorer.newest(tmp_path / 'now', order)
        assert {c['case']: (c['code'], c['outcome']) for c in s['cases']} == {
            'case0002': ('abc1234', 'error'), 'case0003': ('def5678', 'correct')}
        assert s['meta']['commit'] == 'newest of abc1234, def5678'
    older['meta']['seed'] = SEED + 1
    (tmp_path / 'old.json').write_text(json.dumps(older))
    with pytest.raises(SystemExit, match='draws of seeds'):
        scorer.newest(tmp_path / 'now', [tmp_path / 'old.json', tmp_path / 'new.json'])
    newer['meta']['commit'] = 'def5678+dirty'
    (tmp_path / 'new.json').write_text(json.dumps(newer))
    with pytest.raises(SystemExit, match="code 'def5678\\+dirty', not of a commit"):
        scorer.newest(tmp_path / 'now', [tmp_path / 'new.json'])
