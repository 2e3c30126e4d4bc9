"""What refutes a fitted model besides its error (ident/refutations.py), on records of the independent
simulator (tests/independent/rigsim.py): a static friction that no command of the record overcomes, no static
friction where the cart stood still under force."""
from dataclasses import replace

import numpy as np
import pytest
from independent import rigsim

from ipfric_core.analysis.records import load
from ipfric_core.ident.model import load_declared
from ipfric_core.ident.refutations import (
    HOLD_COUNTS,
    crossings,
    never_holds,
    never_starts,
    reversals,
    stops,
    stops_and_starts,
    unheld_travels,
    unseen,
)


def test_a_static_friction_no_command_overcomes_refutes_the_model(tmp_path):
    rec = load(rigsim.write_case('cart_none', tmp_path, duration=20.0), None)
    starts, turns = len(stops_and_starts(rec)), reversals(rec)
    assert starts >= 3 and turns >= 3
    model = load_declared(None, 'exponential', pendulum=False)
    assert never_starts(rec, model) == []
    umax = float(np.max(np.abs(rec.u)))
    push = model['alpha'] * umax                         # the drive's largest force at rest [N]
    at = {k: model.with_values({'Fs_excess': k * push - model['Fc']}) for k in (0.99, 1.01)}

    def everywhere(m):
        """never_starts' reason that the model holds the cart against every command of the record, or None
        (below the largest command, it holds it where the cart started under weaker ones: the next test)."""
        return next((w for w in never_starts(rec, m) if 'every command of the record' in w), None)
    assert everywhere(at[0.99]) is None and never_starts(rec, at[0.99])
    why = never_starts(rec, at[1.01])
    assert len(why) == 1, why
    assert f'yet the cart started from rest {starts} times and reversed its travel {turns} times' in why[0]
    assert f'at most {push:.4g} N' in why[0]
    # a deadzone takes its width off the largest command: the same friction then holds the cart
    dz = at[0.99].with_effect('deadzone', {'deadzone_V': 0.05 * umax})
    assert everywhere(dz) and f'times {0.95 * umax:.4g} V' in everywhere(dz)
    # an offset pushes the cart at rest as the drive does
    assert everywhere(at[1.01].with_effect('offset', {'offset_N': 0.05 * push})) is None
    # a direction dependence lowers the limit one way: (1 - |a|) Fs is what holds the cart
    assert everywhere(at[1.01].with_effect('asymmetry', {'asymmetry': -0.05})) is None
    # a drive play's contact pushes beyond alpha V: not judged so
    assert never_starts(rec, at[1.01].with_effect('drive_backlash', {'drive_backlash_m': 1e-3})) == []


@pytest.mark.parametrize('law', ['viscous', 'dynamic'])
def test_laws_that_do_not_stick_are_not_judged_so(tmp_path, law):
    """The viscous law has no static level; the dynamic law's bristles creep below it (the cart moves)."""
    rec = load(rigsim.write_case('cart_none', tmp_path, duration=20.0), None)
    model = load_declared(None, law, pendulum=False)
    push = model['alpha'] * float(np.max(np.abs(rec.u)))
    if 'Fs_excess' in {p.name for p in model.params}:
        model = model.with_values({'Fs_excess': 2 * push})
    assert never_starts(rec, model) == []


def test_a_pendulum_record_is_not_judged_so(tmp_path):
    rec = load(rigsim.write_case('loop_none', tmp_path, duration=5.0), None)
    model = load_declared(None, 'exponential', pendulum=True)
    push = model['alpha'] * float(np.max(np.abs(rec.u)))
    assert never_starts(rec, model.with_values({'Fs_excess': 2 * push})) == []


def test_reversals_count_the_turns_of_travel_not_the_encoders_dither(tmp_path):
    rec = load(rigsim.write_case('cart_none', tmp_path, duration=5.0), None)
    q = rec.x_resolution
    t = np.arange(4000) * 1e-3
    wave = q * np.round(40 * np.sin(2 * np.pi * 2.0 * t))               # 2 Hz, 40 counts: 16 turns in 4 s
    dither = q * (np.arange(4000) % 2)                                    # one count back and forth
    assert reversals(replace(rec, t=t, x=wave, u=np.zeros(4000), valid=None)) == 16
    assert reversals(replace(rec, t=t, x=wave + dither, u=np.zeros(4000), valid=None)) == 16
    assert reversals(replace(rec, t=t, x=dither, u=np.zeros(4000), valid=None)) == 0


def test_a_cogging_must_repeat_over_the_travel(tmp_path):
    """A ripple is a force that repeats: a cogging whose period fits twice into the cart's travel stands (a
    balancing loop's cart travels some 30 mm: seed 2027's case 199 holds a 14 mm cogging of 2.5 counts), one
    that does not is refuted by the travel, whatever its fit."""
    from ipfric_core.ident.problem import Problem
    from ipfric_core.ident.refutations import contradictions
    rec = load(rigsim.write_case('loop_none', tmp_path, duration=10.0), None)
    travel = float(np.ptp(rec.x))
    model = load_declared(None, 'exponential', pendulum=True).with_effect('cogging', {'cogging_sin_N': 0.01})
    pr = Problem(rec)
    assert contradictions(pr, model.with_values({'cogging_period_m': 0.49 * travel}), 'cogging') == []
    why = contradictions(pr, model.with_values({'cogging_period_m': 0.51 * travel}), 'cogging')
    assert why == [f'cogging period {0.51 * travel * 1e3:.3g} mm: fewer than 2 periods over the travel '
                   f'({travel * 1e3:.3g} mm)']


def test_a_static_friction_the_drive_did_not_overcome_at_a_start_refutes_the_model(tmp_path):
    """Each start from rest is checked against the largest command within BREAKAWAY_S of it: a static level
    between the force of the weakest start and the record's largest force holds the cart where it started
    (a PID cart's log kept 24.5 N, below its largest 28 N, where it had started under 1.5 N)."""
    from ipfric_core.ident.refutations import BREAKAWAY_S
    rec = load(rigsim.write_case('cart_none', tmp_path, duration=20.0), None)
    model = load_declared(None, 'exponential', pendulum=False)
    travel = 2.5 * rec.x_resolution
    starts = [s for s, _ in stops_and_starts(rec)
              if np.max(np.abs(rec.x[s:np.searchsorted(rec.t, rec.t[s] + BREAKAWAY_S)] - rec.x[s])) >= travel]
    weakest = min(starts, key=lambda s: np.max(np.abs(rec.u[np.abs(rec.t - rec.t[s]) <= BREAKAWAY_S])))
    volts = float(np.max(np.abs(rec.u[np.abs(rec.t - rec.t[weakest]) <= BREAKAWAY_S])))
    push = model['alpha'] * volts
    assert push < 0.9 * model['alpha'] * float(np.max(np.abs(rec.u)))      # weaker than the record's largest
    assert never_starts(rec, model.with_values({'Fs_excess': 0.99 * push - model['Fc']})) == []
    why = never_starts(rec, model.with_values({'Fs_excess': 1.01 * push - model['Fc']}))
    assert len(why) == 1 and f't = {rec.t[weakest]:.4g} s' in why[0] and f'{volts:.4g} V' in why[0], why


def test_stale_readings_after_an_overrun_are_no_stop(tmp_path):
    """A sample overrun repeats the reading before (marked invalid on loading): frozen so for 60 ms in
    motion, the cart has not stopped and started again; a stop is read on the valid readings."""
    from ipfric_core.ident.refutations import STOP_S
    rec = load(rigsim.write_case('cart_none', tmp_path, duration=20.0), None)
    before = stops_and_starts(rec)
    speed = np.abs(np.gradient(rec.x, rec.t))
    k = int(np.argmax(speed))                            # the fastest reading: moving, far from a stop
    n = int(np.ceil(1.2 * STOP_S / rec.dt))
    x, valid = rec.x.copy(), rec.valid_mask.copy()
    x[k + 1:k + 1 + n], valid[k + 1:k + 1 + n] = x[k], False
    stale = replace(rec, x=x, valid=valid)
    assert stops_and_starts(replace(stale, valid=None)) != before      # read as readings, a stop appears
    assert stops_and_starts(stale) == before


def test_a_crossing_of_a_drive_play_is_counted_in_readings():
    """The motor side's crossings of its play, from its contact side at each reading: a reversal of the
    contact (forward to backward or back) is one, however many readings in the play between; a return to
    the same side is none. The rule that refutes a play crossed between two readings counts these, not
    the time (with jittered stamps, two readings' span fell to 10.9 ms against a median period of 5.7 ms
    and a play the data show was refused)."""
    side = np.array([0, 1, 1, 0, -1, -1, 0, 0, 1, 0, 1, 1, -1, 0, 0, 0, 1], float)
    before, after = crossings(side)
    assert before.tolist() == [2, 5, 11, 12] and after.tolist() == [4, 8, 12, 16]
    assert (after - before).tolist() == [2, 3, 1, 4]
    assert [len(a) for a in crossings(np.zeros(5))] == [0, 0] and [len(a) for a in crossings(np.ones(1))] == [0, 0]
    # the rule: a reading in the play at the median crossing, whatever the span's time (it takes none)
    assert unseen(np.array([1, 1, 2])) and unseen(np.array([1, 1, 1, 2, 3, 3]))
    assert not unseen(np.array([2, 2, 1])) and not unseen(np.array([1, 2, 3, 2]))


def _through_play(x: np.ndarray, play: float, count: float) -> np.ndarray:
    """Readings of a cart at ``x`` [m] taken through an encoder play [m], in whole counts (this test's own
    formula: the reading moves only where the cart pushes an edge of the play)."""
    r = np.empty_like(x)
    r[0] = x[0]
    for k in range(1, len(x)):
        r[k] = min(max(r[k - 1], x[k] - 0.5 * play), x[k] + 0.5 * play)
    return count * np.round(r / count)


@pytest.mark.parametrize('case, play_counts', [('cart_none', 3), ('cart_none', 100), ('loop_none', 20)])
def test_an_encoder_play_is_at_most_what_the_cart_crosses_while_its_readings_turn(tmp_path, case, play_counts):
    """Behind a play the readings stand while the cart turns and crosses it, no faster than the cart ever
    moves: readings taken through a true play allow it, and a play wider than the turns allow is refuted (a
    real cart's log was fitted with a 68 mm play where its readings turned within 20 ms at 0.9 m/s at most)."""
    from ipfric_core.ident.problem import Problem
    from ipfric_core.ident.refutations import contradictions, widest_play
    rec = load(rigsim.write_case(case, tmp_path, duration=20.0), None)
    q = rec.x_resolution
    played = replace(rec, x=_through_play(rec.x, play_counts * q, q))
    limit, turn, fastest = widest_play(played)
    assert limit >= play_counts * q                     # a true play is never refuted
    model = load_declared(None, 'exponential', pendulum=rec.theta is not None).with_effect('backlash')
    pr = Problem(played)
    assert contradictions(pr, model.with_values({'backlash_m': play_counts * q}), 'backlash') == []
    why = contradictions(pr, model.with_values({'backlash_m': 1.01 * limit}), 'backlash')
    assert len(why) == 1 and f'within {turn * 1e3:.3g} ms' in why[0] and f'{fastest:.3g} m/s' in why[0], why


@pytest.mark.parametrize('case, duration', [('cart_none', 20.0), ('loop_none', 30.0)])
def test_no_static_friction_where_the_cart_stood_still_under_force_refutes_the_viscous_law(tmp_path, case, duration):
    """A rig with Coulomb friction (the independent simulator's) stands still under commands a cart without
    static friction would have followed, on the cart alone and in a balancing loop: the viscous law is refuted
    at those stops; the same rig without Coulomb friction (mu_c = mu_s = 0) stops only
    where nothing pushes it, and the law stands. The laws that stick are not judged so."""
    spec = rigsim.CASES[case]
    pendulum = spec['experiment'] == 'loop'
    model = load_declared(None, 'viscous', pendulum=pendulum)
    rec = load(rigsim.write_case(case, tmp_path, duration=duration), None)
    moved = [travel / rec.x_resolution for travel, _, _ in unheld_travels(rec, model)]
    beyond = sum(m >= HOLD_COUNTS for m in moved)
    assert beyond >= 3, moved
    why = never_holds([rec], model)
    assert len(why) == 1 and f'stood still at {beyond} of {len(moved)} stops' in why[0], why
    assert f'{max(moved):.3g} encoder counts' in why[0]
    assert never_holds([rec], load_declared(None, 'exponential', pendulum=pendulum)) == []
    assert never_holds([rec], model.with_effect('drive_backlash', {'drive_backlash_m': 1e-3})) == []
    smooth = rigsim.simulate(dict(spec, rig_overrides={'mu_c': 0.0, 'mu_s': 0.0}), duration)
    smooth['truth']['case'] = case
    rec = load(rigsim.write_case(case, tmp_path / 'viscous', data=smooth), None)
    assert len(stops(rec)) >= 3
    assert max(travel for travel, _, _ in unheld_travels(rec, model)) < rec.x_resolution
    assert never_holds([rec], model) == []
