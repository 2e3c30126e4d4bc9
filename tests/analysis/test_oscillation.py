"""Oscillation classification on runs whose answer is known."""
import math

import numpy as np
import pytest

from ipfric_core.analysis.oscillation import classify, crossing_period, spectral_period
from ipfric_core.design import paper
from ipfric_core.physics.closedloop import run_closed_loop
from ipfric_core.run.scenario import scenario_from_ros_params

PLANT = {'M': 0.815, 'm': 0.21, 'l': 0.305, 'g': 9.8, 'alpha': 1.7189, 'beta': 7.682}
EXP = {'model': 'exponential', 'eps': 3.0, 'mu_s': 0.0861, 'mu_c': 0.04287, 'v_s': 0.105, 'gamma': 2.0}


def analysed(gain, theta0, delay=0.0, exact=False, duration=30.0):
    sim = {'plant': PLANT, 'friction': EXP, 'theta0': theta0}
    if exact:
        sim.update(cart_resolution=0.0, angle_resolution=0.0)
    s = scenario_from_ros_params(sim, {'gain': list(gain), 'delay': delay})
    tr = run_closed_loop(s.make_rig(), s.make_controller(), duration)
    return classify(tr.t, tr.measured[:, 0], tr.measured[:, 1],
                    (s.sim.cart_resolution, s.sim.angle_resolution), ended_fallen=tr.end_reason != 'duration')


def test_period_estimators_agree_on_a_sine():
    t = np.arange(0, 20, 1e-3)
    y = 0.01 * np.sin(2 * np.pi * t / 2.5 + 0.3)
    assert crossing_period(t, y) == pytest.approx(2.5, rel=1e-4)
    assert spectral_period(t, y) == pytest.approx(2.5, rel=5e-3)


def test_old_gain_is_a_sticking_limit_cycle():
    o = analysed(paper.GAIN_15_VISCOUS, 0.02)
    assert o.cls == 'limit_cycle'
    assert 0.008 < o.x_p2p < 0.03
    assert o.period_crossings and o.period_spectrum
    assert o.period_crossings == pytest.approx(o.period_spectrum, rel=0.1)
    assert 1.0 < o.period_crossings < 6.0
    assert o.stick_fraction > 0.2


def test_new_gain_with_exact_sensors_settles():
    o = analysed(paper.GAIN_23_EXPONENTIAL, 0.06, exact=True)
    assert o.cls == 'settled'
    assert 0.0 < o.transition_time < 20.0


def test_large_delay_falls():
    o = analysed(paper.GAIN_23_EXPONENTIAL, math.radians(3), delay=0.06, duration=10.0)
    assert o.cls == 'fallen'


def test_growing_oscillation_is_recognised():
    t = np.arange(0, 20, 1e-3)
    x = 1e-3 * np.exp(0.2 * t) * np.sin(2 * np.pi * t)
    assert classify(t, x, 0.1 * x).cls == 'growing'


def test_slow_cycle_seen_for_two_periods_is_a_cycle():
    """Exact sensors, sgn friction: the old gain's cycle has a period near 5 s, two in the window."""
    o = analysed(paper.GAIN_15_VISCOUS, 0.02, exact=True)
    assert o.cls == 'limit_cycle' and o.periods_agree
    assert 4.0 < o.period_crossings < 7.0
    assert 0.008 < o.x_p2p < 0.03


def test_creep_and_irregular_chatter():
    t = np.arange(0, 20, 1e-3)
    creep = 2e-3 * np.exp(-t / 30) + 2e-4 * np.sin(2 * np.pi * t / 25)   # less than 1.5 periods visible
    assert classify(t, creep, 0 * t).cls == 'settled'
    rng = np.random.default_rng(1)
    chatter = 1e-3 * np.round(np.cumsum(rng.standard_normal(len(t))) / 40 % 3)  # irregular jumps
    o = classify(t, chatter, 0 * t)
    assert o.cls == 'irregular' and not o.periods_agree


def test_final_regime_time_marks_the_end_of_the_transient():
    t = np.arange(0, 20, 1e-3)
    x = 0.02 * np.exp(-t) + 1e-3 * np.sin(2 * np.pi * t)      # decays onto a 2 mm cycle
    o = classify(t, x, 0 * t)
    assert o.cls == 'limit_cycle'
    # the transient's excess over the cycle falls below 20 % of its p2p (0.4 mm) at ln(50) = 3.9 s,
    # seen at the last peak of the cycle before that
    assert np.log(50) - 1.0 < o.transition_time < np.log(50)
