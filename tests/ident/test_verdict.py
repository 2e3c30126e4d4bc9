"""The verdict (ident/judging.verdict) on a record of the independent simulator: the error left and what
the encoders' rounding alone would leave, both in % of the measured motion."""
from dataclasses import replace

import numpy as np
import pytest
from independent import rigsim

from ipfric_core.analysis.records import load
from ipfric_core.ident.judging import rounding_model, verdict
from ipfric_core.ident.ladder import run_ladder
from ipfric_core.ident.model import load_declared
from ipfric_core.ident.problem import Problem
from ipfric_core.ident.shooting import quantization_floor


def test_the_floor_is_a_share_of_the_measured_motion_even_for_a_model_that_hardly_moves(tmp_path):
    rec = load(rigsim.write_case('cart_none', tmp_path, duration=20.0), None)
    pv = Problem(rec.split(0.6)[1])
    model = load_declared(None, 'exponential', pendulum=False)
    stuck = model.with_values({'Fc': 8 * model['Fc'], 'Fs_excess': 8 * model['Fs_excess']})   # hardly moves
    got = {}
    for name, m in (('declared', model), ('stuck', stuck)):
        v = got[name] = verdict(pv, m)
        # one denominator: the counts' ratio is the percents' ratio
        assert v['floor_percent'] == pytest.approx(v['floor_counts'] * v['unexplained_percent']
                                                   / v['unexplained_counts'], rel=0.05), (name, v)
    assert got['stuck']['unexplained_percent'] > 50       # most of the motion left ...
    assert got['stuck']['floor_percent'] < 5              # ... beside a rounding that leaves a few %, not a share
    assert not got['stuck']['explained']                 # of the little the model moves


def test_a_play_no_sensor_reads_does_not_raise_the_floor(tmp_path):
    """The floor is what the encoders' rounding leaves, not the error of starting a play's hidden position
    from an estimate: a model with a 30 mm encoder play and one with a drive play are judged against the
    floor of the same model with the play closed (the drive's motor side then moves with the cart)."""
    rec = load(rigsim.write_case('cart_none', tmp_path, duration=20.0), None)
    pv = Problem(rec.split(0.6)[1])
    model = load_declared(None, 'exponential', pendulum=False)
    loose = model.with_effect('backlash', {'backlash_m': 0.03})
    win = pv.blocks[0][1]
    own = quantization_floor(loose.vectors(), pv.rec, win, 'x')['x_floor_counts']
    plain = verdict(pv, model)['floor_counts']
    assert own > 3 * plain                                   # the play's start estimate, not rounding
    assert verdict(pv, loose)['floor_counts'] == pytest.approx(plain, rel=1e-9)
    drive = model.with_effect('drive_backlash', {'drive_backlash_m': 1e-3, 'drive_mass_kg': 0.2,
                                                 'drive_stiffness_N_per_m': 1e5, 'drive_damping_Ns_per_m': 20.0})
    closed = rounding_model(drive)
    assert closed['drive_backlash_m'] == 0.0 and closed['M'] == pytest.approx(model['M'] + 0.2)
    assert rounding_model(model) == model


def test_a_validation_part_where_nothing_moves_judges_nothing(tmp_path):
    """A cart standing still with no command in the validation part: the model replays it exactly (0 counts
    left, 0 % of no motion), which explains nothing. The verdict says the data judge nothing and is not
    "explained"; on the moving record it judges the cart."""
    rec = load(rigsim.write_case('cart_none', tmp_path, duration=20.0), None)
    val = rec.split(0.6)[1]
    model = load_declared(None, 'exponential', pendulum=False)
    moving = verdict(Problem(val), model)
    assert moving['judged_on'] == ['x'] and moving['blocks']['x']['motion_counts'] > 100
    still = replace(val, x=np.full_like(val.x, val.x[0]), u=np.zeros_like(val.u))
    v = verdict(Problem(still), model)
    assert v['blocks']['x']['motion_counts'] == 0.0 and v['unexplained_counts'] == pytest.approx(0.0, abs=1e-9)
    assert v['judged_on'] == [] and not v['explained']
    assert v['reason'].startswith('not judged: nothing moves by 2 counts RMS within the validation windows (the cart '
                                  'moves 0 counts RMS')


@pytest.mark.slow
def test_a_time_limit_stops_the_ladder_between_rounds_and_says_so(tmp_path):
    """With a time limit that round 1 outlasts, round 1 runs whole and keeps its explanation, no round
    follows, and the verdict says where the ladder stopped (a 30 ms real log whose dynamic law took hours
    over four rounds: docs/identification.md)."""
    rec = load(rigsim.write_case('cart_deadzone', tmp_path, duration=20.0), None)
    est, val = rec.split(0.6)
    res = run_ladder(est, val, load_declared(None, 'exponential', pendulum=False), time_limit=1e-3)
    assert [r['round'] for r in res['rounds']] == [1] and res['rounds'][0]['kept'], res['rounds']
    assert len(res['steps']) == 2 and {t['round'] for t in res['tried']} == {1}
    v = res['verdict']
    assert v['stopped']['before_round'] == 2 and v['stopped']['elapsed_s'] > v['stopped']['time_limit_s'] == 1e-3
    assert 'stopped before round 2 of at most 4' in v['reason'] and 'the time limit is 0.001 s' in v['reason'], v
