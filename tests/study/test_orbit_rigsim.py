"""ipfric's periodic orbit against the independent rig simulator (Figure 7, gain (15), exact sensors).

``find_orbit`` predicts the limit cycle of the sampled closed loop by shooting and Newton,
without a long simulation. tests/design/test_orbit.py checks it against ipfric's own
simulator, which runs the same compiled plant, friction and controller functions: that
proves consistency, not correctness. Here the cycle comes from tests/independent/rigsim.py,
written separately from the paper's equations and importing nothing from ipfric_core (its
own RK4 at 0.1 ms substeps with the sign of x' frozen per step, regula falsi for the stops,
its own stick test and velocity filter), run for 60 s and measured over the last 30 s.

The same loop on both sides (test_both_sides_describe_the_same_loop checks the numbers):
Table 1 plant and Table 3 exponential Stribeck friction of eq. (8) (gamma = 2,
F_N = (M + m) g, true sticking) of config/fig7_old_gain_exponential.yaml = rigsim's
RIGS['quanser']; gain (15) = K_PAPER; 1 kHz; velocities the backward differences low-passed
at 20 Hz, v_k = e v_k-1 + (1 - e) (y_k - y_k-1) / Ts with e = exp(-2 pi 20 Hz Ts) (the
scenario's filter is this one, written independently on each side); the 10 V limit (never
reached, |V| < 0.7 V on the cycle); no delay; exact sensors (encoder counts 0 on both sides,
as in the paper's simulations); the scenario's start theta0 = 0.02 rad.

Tolerance. Measured: orbit x p2p 1.4370426 cm, period 5.4122974 s, largest multiplier
1.4e-5; rigsim's cycle agrees to about 1e-8 relative in both. That floor comes from the
integrators (rigsim at 1 ms substeps instead of 0.1 ms moves its cycle by < 1e-9) and the
crossing times interpolated between samples (per-cycle scatter of the period 1.3e-7). A
mismatch of 0.1 % in one constant moves the cycle by far more: mu_s 1.0e-3 (x p2p),
g 3.4e-3, l 9e-4, eps (1 %) 2.6e-3, filter corner (1 %) 1.0e-3, mu_c 3.9e-5 (period).
rel = 1e-5 is 1000 times the agreement found and below each of these. The sticking time
is counted in whole samples (about one sample of phase per sticking phase, two phases per
cycle): abs 1e-3 of the period, about 5 samples.
"""
import math
from pathlib import Path

import numpy as np
import pytest
from independent import rigsim as rs

from ipfric_core.physics.friction import (
    EXPONENTIAL,
    FP_ASYM,
    FP_ASYM_V,
    FP_EPS,
    FP_FN,
    FP_GAMMA,
    FP_MODEL,
    FP_MU_C,
    FP_MU_S,
    FP_SMOOTH,
    FP_V_S,
)
from ipfric_core.run.scenario import load_scenario
from ipfric_core.study.orbit import find_orbit, loop_numbers
from ipfric_core.study.variants import exact_sensors

CONFIG = Path(__file__).resolve().parents[2] / 'config' / 'fig7_old_gain_exponential.yaml'
RIG = rs.RIGS['quanser']
DURATION, SINCE = 60.0, 30.0        # rigsim run and start of the measured window [s]
REL = 1e-5                          # cycle agreement (see the module docstring)


@pytest.fixture(scope='module')
def scenario():
    """Figure 7 with exact sensors (as ``ipfric orbit --sensors exact``)."""
    scn = load_scenario(CONFIG)
    return exact_sensors(scn)


@pytest.fixture(scope='module')
def loop(scenario):
    """The sampled loop find_orbit solves (as the CLI builds it with ``loop_of`` at delay 0)."""
    return loop_numbers(scenario.make_rig().loop_spec(), scenario.make_controller().loop_spec(), 0.0)


@pytest.fixture(scope='module')
def rig_cycle(scenario):
    """rigsim's closed loop with exact readings: cart peak-to-peak [m] and mean period [s] between
    rises of theta through the middle of its swing (crossings interpolated between samples),
    the fraction of samples stuck and sticking phases per cycle, over whole cycles after SINCE."""
    spec = dict(rs.CASES['loop_none'], rig_overrides={'x_res': 0.0, 'theta_res': 0.0},
                theta0=scenario.sim.theta0)
    out = rs.simulate(spec, duration=DURATION)
    keep = out['t'] >= SINCE
    t, x = out['t'][keep], out['state']['x'][keep]
    th, v = out['state']['theta'][keep], out['state']['v'][keep]
    level = 0.5 * (th.max() + th.min())
    up = np.flatnonzero((th[:-1] < level) & (th[1:] >= level))
    assert len(up) >= 4, 'rigsim does not keep oscillating'
    cross = t[up] + (level - th[up]) / (th[up + 1] - th[up]) * (t[up + 1] - t[up])
    stuck = v[up[0] + 1:up[-1] + 1] == 0.0
    return {'x_p2p': float(np.ptp(x)), 'period': float(np.mean(np.diff(cross))),
            'period_scatter': float(np.ptp(np.diff(cross))), 'stuck_fraction': float(stuck.mean()),
            'sticks': np.count_nonzero(stuck[1:] & ~stuck[:-1]) / (len(up) - 1),
            'max_volts': float(np.abs(out['voltage'][keep]).max())}


def test_both_sides_describe_the_same_loop(loop):
    M, m, g = RIG['M'], RIG['m'], RIG['g']
    assert loop.plant == pytest.approx((M, m, RIG['l'], g, RIG['alpha'], RIG['beta']), rel=1e-15)
    f = loop.friction
    assert f[FP_MODEL] == EXPONENTIAL and f[FP_SMOOTH] == 0.0 and f[FP_GAMMA] == 2.0
    assert (f[FP_EPS], f[FP_MU_S], f[FP_MU_C], f[FP_V_S]) == pytest.approx(
        (RIG['eps'], RIG['mu_s'], RIG['mu_c'], RIG['v_s']), rel=1e-15)
    assert f[FP_FN] == pytest.approx((M + m) * g, rel=1e-14)
    assert f[FP_ASYM] == f[FP_ASYM_V] == 0.0
    assert loop.extra_force[0] == loop.extra_force[1] == loop.extra_force[3] == 0.0   # no cogging, no offset
    assert loop.gain == pytest.approx(rs.K_PAPER, rel=1e-15)
    a, dt, delay, vlimit = loop.control
    assert loop.dt == dt == RIG['Ts']
    assert a == pytest.approx(math.exp(-2 * math.pi * rs.FILTER_HZ * RIG['Ts']), rel=1e-14)
    assert delay == 0.0 and loop.switch == 0.0 and loop.delay == 0.0
    assert vlimit == rs.VMAX
    assert loop.resolution == (0.0, 0.0)                                # exact readings
    assert loop.sensors == (0.0, 0.0, 0.0) and loop.drive == (0.0, 0.0, 0.0)


def test_orbit_matches_the_independent_simulator(loop, rig_cycle):
    orbit = find_orbit(loop)
    assert orbit.stable and orbit.largest_multiplier < 1.0
    assert rig_cycle['max_volts'] < rs.VMAX                              # the limit plays no part
    assert orbit.x_p2p == pytest.approx(rig_cycle['x_p2p'], rel=REL)
    assert orbit.period == pytest.approx(rig_cycle['period'], rel=REL)
    assert rig_cycle['period_scatter'] < REL * orbit.period            # rigsim has settled on the cycle
    assert orbit.stuck_fraction == pytest.approx(rig_cycle['stuck_fraction'], abs=1e-3)
    assert orbit.sticks == rig_cycle['sticks'] == 2
