"""Exact stick-slip integration: sticks, breaks away, re-sticks, no chatter, no stall."""
import math

import numpy as np
import pytest

from ipfric_core.physics.params import FrictionParams, PlantParams
from ipfric_core.physics.plant import CartPendulum
from ipfric_core.physics.simulate import Simulator

PLANT = PlantParams()
EXP = FrictionParams('exponential', eps=3.0, mu_s=0.0861, mu_c=0.04287, v_s=0.105, gamma=2.0)
LIMIT = 0.0861 * PLANT.normal_force  # 0.865 N = alpha * 0.503 V


def run(sim, schedule, dt=1e-3):
    """schedule: list of (duration, voltage). Returns t, x, v, stuck arrays."""
    rows = []
    for duration, volt in schedule:
        for _ in range(int(round(duration / dt))):
            sim.step(volt, dt)
            rows.append((sim.t, sim.state[0], sim.state[2], sim.stuck))
    a = np.array(rows)
    return a[:, 0], a[:, 1], a[:, 2], a[:, 3].astype(bool)


def test_sticks_breaks_away_and_resticks():
    # pendulum hanging down (theta = pi), at rest
    sim = Simulator(CartPendulum(PLANT, EXP), [0.0, math.pi, 0.0, 0.0])
    t, x, v, stuck = run(sim, [(0.5, 0.45), (0.6, 1.2), (1.5, 0.0)])
    # 0.45 V * alpha = 0.77 N < mu_s F_N: the cart does not move at all
    assert np.all(stuck[:500]) and np.all(x[:500] == 0.0)
    # 1.2 V breaks away at once and slides forward
    assert not stuck[500] and x[1099] > 0.02 and np.all(v[501:1100] > 0)
    # with 0 V it decelerates, stops, and stays stuck (the swinging pendulum cannot move it)
    assert np.all(stuck[-500:])
    assert np.ptp(x[-500:]) == 0.0
    # three transitions, no chatter around v = 0
    assert 3 <= sim.events <= 4
    assert t[-1] == pytest.approx(2.6)


def test_a_friction_rising_with_speed_breaks_away_at_its_static_level():
    """mu_s below mu_c (the exponential law's curve rising with speed): the cart holds below mu_s F_N,
    breaks away above it and slides slowly, where the level is near mu_s F_N, but a push between
    the two levels cannot drive it fast: the level it meets at speed is mu_c F_N."""
    rising = FrictionParams('exponential', eps=3.0, mu_s=0.03, mu_c=0.0861, v_s=0.02, gamma=2.0)
    fn = PLANT.normal_force
    sim = Simulator(CartPendulum(PLANT, rising), [0.0, math.pi, 0.0, 0.0])
    held = 0.9 * 0.03 * fn / PLANT.alpha             # 90 % of the static level
    between = 0.5 * (0.03 + 0.0861) * fn / PLANT.alpha
    t, x, v, stuck = run(sim, [(0.5, held), (2.0, between)])
    assert np.all(stuck[:500]) and np.all(x[:500] == 0.0)
    assert not stuck[520] and np.all(v[520:] > 0)
    # sliding, the force balances the level between mu_s and mu_c F_N: a speed of order v_s, not the
    # several m/s a Coulomb level of mu_s F_N would give over 2 s
    assert 0.5 * 0.02 < v[-1] < 3 * 0.02
    assert FrictionParams.from_dict({'model': 'exponential', 'eps': 3, 'mu_s': 0.03, 'mu_c': 0.0861, 'v_s': 0.02,
                                     'gamma': 2}) == rising


def test_pendulum_reaction_breaks_the_cart_loose():
    """A swinging pendulum alone pushes the cart past static friction (held force includes it)."""
    sim = Simulator(CartPendulum(PLANT, EXP), [0.0, math.pi + 0.8, 0.0, 4.0])
    applied = sim.held_force(sim.state, 0.0)
    assert abs(applied) > LIMIT  # m l sin(th) th'^2 - 0.75 m g sin(th) cos(th) = -1.5 N
    sim.step(0.0, 1e-3)
    assert not sim.stuck and abs(sim.state[0]) > 0.0


def test_held_force_makes_sliding_acceleration_vanish():
    m = CartPendulum(PLANT, EXP)
    th, w, F = 0.3, -1.1, 0.7
    applied = m.held_force(th, w, F)
    xdd, thdd = m.accelerations(th, w, F - applied)
    assert xdd == pytest.approx(0.0, abs=1e-12)
    assert thdd == pytest.approx(m.stuck_theta_acceleration(th))


def test_event_location_converges():
    """Halving the RK4 substep ten times changes the stick-slip trajectory by < 1e-7 m."""
    def traj(h):
        sim = Simulator(CartPendulum(PLANT, EXP), [0.0, math.pi - 0.5, 0.0, 0.0], substep=h)
        return run(sim, [(0.3, 0.0), (0.4, 1.0), (1.0, -0.2)])[1]
    coarse, fine = traj(2.5e-4), traj(2.5e-5)
    assert np.max(np.abs(coarse - fine)) < 1e-7


def test_smooth_and_dynamic_laws_never_stick():
    for fr in (EXP.replace(smoothing='tanh'),
               FrictionParams('dynamic', eps=3.0, mu_s=0.0861, mu_c=0.04287, v_s=0.105, gamma=2.0,
                              sigma0=121.0, sigma1=70.0)):
        sim = Simulator(CartPendulum(PLANT, fr), [0.0, math.pi, 0.0, 0.0])
        _, x, _, stuck = run(sim, [(0.3, 0.45)])
        assert not stuck.any() and x[-1] > 0.0  # creeps below breakaway: no true sticking
