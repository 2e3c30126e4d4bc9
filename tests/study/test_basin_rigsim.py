"""The edge of the upright's basin against the independent rig simulator (Figure 9 plant with
tanh(100 v) friction, gain (23), feedback delay 90 ms, exact sensors).

With the delay tau = 0.090 s the upright is stable but its basin is small: started from
(x, theta, x', theta') = (0, theta0, 0, 0), the run settles to rest for theta0 below a
threshold theta0* and the pendulum falls above it. The run started at theta0* lingers for
several seconds on an unstable periodic orbit (one Floquet multiplier 5.08 outside the unit
circle): theta0* is where the start crosses that orbit's stable manifold. ipfric finds both
with ``study.basin.basin_edge`` (bisection of theta0 with runs of its compiled loop, then
Newton from the run at the edge); here the threshold and
the lingering cycle also come from tests/independent/rigsim.py, written separately from the
paper's equations and importing nothing from ipfric_core (its own RK4 at 0.1 ms substeps
with tanh(delta v) in place of sgn(v), its own velocity filter and delay buffer), bisected
with a settle/leave rule of its own.

The same loop on both sides (test_both_sides_describe_the_same_loop checks the numbers):
Table 1 plant and Table 3 exponential friction of eq. (8) (gamma = 2, F_N = (M + m) g) of
config/fig9_new_gain_exponential.yaml = rigsim's RIGS['quanser'], sgn(v) smoothed to
tanh(100 v) (no sticking); gain (23) with V = +K . (x, theta, x', theta') on both sides (the
sign checked beforehand: without delay and with the sgn law, rigsim's and ipfric's Figure 9
runs agree to 3e-11 m over 20 s; the opposite sign falls in 0.18 s); 1 kHz; the 20 Hz
velocity filter; the 10 V limit; exact sensors (encoder counts 0); the feedback delay of 90
samples, V_k = K . r_(k-90) with r_j = (x, theta, x', theta') estimated at sample j and, for
k < 90, the first reading at rest (x_0, theta0, 0, 0) (eq. 30, rigsim's
"feedback_delay_samples"). The track limits differ (ipfric 0.4 m, rigsim 0.35 m): above the
threshold rigsim's runs leave its track before the pendulum passes 30 deg; either counts as
leaving, so only the settle/leave split uses them.

Settle/leave rules, each side its own, over RUN = 40 s: rigsim leaves when its run stops
early (|theta| > 0.5236 rad or |x| > 0.35 m, "stop_when_fallen") and settles when the whole
run stays on the track with |theta| < 1e-6 theta0 over its last second; ipfric's
``basin.fate`` leaves when the loop falls, reaches the track's end or its swing grows 20-fold
and settles when the swing over 0.5 s falls to 1e-4 of the first window's. Any other outcome
of a rigsim run fails the test. Both bisect theta0 in [0.05, 0.1] deg down to a bracket of
1e-13 relative (about 43 runs each).

Threshold. Measured: theta0* = 0.0837744032034 deg (ipfric) and 0.0837744031965 deg
(rigsim, bisected to the last bit): they agree to 8e-11 relative. rigsim at 1 ms substeps
moves its threshold by 2.3e-8 (the integrators' floor; ipfric runs 0.25 ms substeps). A
mismatch of 0.1 % in one constant moves the threshold by far more (rigsim): mu_c 9.7e-6, v_s 2.0e-5,
filter corner 3.1e-5, K_x 8.7e-5, eps 1.1e-4, beta 2.8e-4, m 4.8e-4, delta 1.4e-3, M 1.8e-3,
g 1.9e-3, mu_s 2.4e-3, alpha 2.6e-3, K_theta 2.3e-3, l 3.7e-3, K_x' 6.0e-3, K_theta' 5.5e-3.
REL = 1e-6 is 10^4 times the agreement and 10 times below the smallest of these (mu_c).

Lingering cycle. ipfric's orbit (``basin_edge``'s Newton from its run at the edge): cart p2p
1.64561 mm, theta p2p 3.51326e-3 rad, period 0.495768 s, largest multiplier 5.084. rigsim's
runs at both ends of its bracket stay within 1 % of that swing for 15-16 cycles (7.4-7.9 s)
before they settle or leave; the cycle that repeats itself best (smallest change of the
swings to the next cycle, the 10th or 11th) matches the orbit to 6e-5 in the cart's and the
angle's swing and 1e-5 in the period. That floor is the run itself, not the simulators: it
approaches the orbit along a direction with multiplier about 0.67 (1.4e-3 off in both swings
on the second cycle) while a bracket of 1e-13 lets it depart along the unstable one after
about 15 cycles. The cart's swing is taken with the cycle's net drift removed (x minus the
straight line through its values at the two crossings; no change on a periodic orbit): the
drift of the cart's centre on the approach otherwise adds 8e-4 to 1.2e-3 there. Tolerances:
rel 5e-4 for the swings and 1e-4 for the period, 8-10 times the measured agreement. A 0.1 %
error in M, l, g, alpha, mu_s, delta, K_theta or K_x' moves the orbit's swings by 1.3e-3 to
7e-3 (m 4.6e-4, beta 2.7e-4, K_x 2.4e-4, eps 1.0e-4, mu_c 1e-5: those the threshold test
catches).
"""
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from independent import rigsim as rs

from ipfric_core.physics import friction as fr
from ipfric_core.physics.closedloop import LS_HISTORY
from ipfric_core.study.basin import basin_edge
from ipfric_core.study.orbit import loop_numbers
from ipfric_core.study.variants import load_variant

CONFIG = Path(__file__).resolve().parents[2] / 'config' / 'fig9_new_gain_exponential.yaml'
RIG = rs.RIGS['quanser']
GAIN = (70.7107, 304.9273, 143.3152, 61.0833)   # eq. (23), V = K . (x, theta, x', theta')
DELTA = 100.0                                   # tanh(delta v) in place of sgn(v) [s/m]
DELAY, DELAY_SAMPLES = 0.090, 90                # feedback delay [s], [samples at 1 kHz]
RUN = 40.0                                      # each run of the bisections [s]
BOUNDS = (0.05, 0.1)                            # theta0 bracket [deg]: settles, falls
BRACKET = 1e-13                                 # relative width the bisections stop at
REL = 1e-6                                      # threshold agreement (see the module docstring)
SWING_REL, PERIOD_REL = 5e-4, 1e-4              # lingering cycle against the orbit (ditto)
QUIET = 1e-6                                    # settled: |theta| below QUIET theta0
SPEC = dict(rs.CASES['loop_none'], rig_overrides={'x_res': 0.0, 'theta_res': 0.0}, K=list(GAIN),
            smoothing={'delta': DELTA}, feedback_delay_samples=DELAY_SAMPLES, stop_when_fallen=True)


@pytest.fixture(scope='module')
def base():
    """Figure 9 with exact sensors and tanh(100 v) (as ``ipfric sweep --sensors exact``)."""
    return load_variant(CONFIG, 'exact', 'tanh')


def _loop(base, theta0):
    """ipfric's sampled loop from (0, theta0, 0, 0) at the delay DELAY."""
    s = replace(base, sim=replace(base.sim, theta0=theta0), controller=replace(base.controller, delay=DELAY))
    return loop_numbers(s.make_rig().loop_spec(), s.make_controller().loop_spec(), DELAY)


def _bisect(leaves):
    """theta0 bracket [deg] of the edge; ``leaves(theta0 [rad])`` -> (True/False, run). Returns
    (settling end, falling end, the runs at those ends)."""
    lo, hi = BOUNDS
    assert not leaves(math.radians(lo))[0] and leaves(math.radians(hi))[0]
    runs = {}
    while hi - lo > BRACKET * hi:
        mid = 0.5 * (lo + hi)
        up, run = leaves(math.radians(mid))
        if up:
            hi, runs['falls'] = mid, run
        else:
            lo, runs['settles'] = mid, run
    return lo, hi, runs


def _rigsim_leaves(theta0):
    out = rs.simulate(dict(SPEC, theta0=theta0), duration=RUN)
    if out['truth']['end'] != 'duration':
        return True, out
    quiet = np.abs(out['state']['theta'][out['t'] > RUN - 1.0]).max() < QUIET * theta0
    assert quiet, f'rigsim neither settles nor leaves from theta0 = {theta0!r} rad in {RUN} s'
    return False, out


@pytest.fixture(scope='module')
def rig_edge():
    return _bisect(_rigsim_leaves)


@pytest.fixture(scope='module')
def ipfric_edge(base):
    """``basin_edge`` over BOUNDS: (settling end [deg], falling end [deg], the Edge)."""
    edge = basin_edge(lambda theta0: _loop(base, theta0), *(math.radians(b) for b in BOUNDS), rtol=BRACKET,
                      duration=RUN)
    return math.degrees(edge.settles_below), math.degrees(edge.leaves_from), edge


@pytest.fixture(scope='module')
def orbit(ipfric_edge):
    """The unstable orbit ``basin_edge`` finds on the edge (Newton from the run at the edge)."""
    edge = ipfric_edge[2]
    assert edge.orbit is not None, edge.why
    return edge.orbit


def _cycles(out):
    """rigsim run -> per cycle between rises of theta through 0 (crossings interpolated between
    samples): period [s], theta p2p [rad], cart p2p without the cycle's net drift [m], start [s]."""
    t, x, th = out['t'], out['state']['x'], out['state']['theta']
    up = np.flatnonzero((th[:-1] < 0.0) & (th[1:] >= 0.0))
    f = -th[up] / (th[up + 1] - th[up])
    tc, xc = t[up] + f * (t[up + 1] - t[up]), x[up] + f * (x[up + 1] - x[up])
    swing, cart = [], []
    for i in range(len(up) - 1):
        s = slice(up[i] + 1, up[i + 1] + 1)
        drift = (xc[i + 1] - xc[i]) / (tc[i + 1] - tc[i])
        swing.append(np.ptp(th[s]))
        cart.append(np.ptp(x[s] - drift * (t[s] - tc[i])))
    return np.diff(tc), np.array(swing), np.array(cart), tc


def _lingering(out):
    """The cycle that repeats itself best (smallest relative change of theta's and the cart's
    swings to the next cycle) and the stretch of cycles around it whose theta swing stays within
    1 % of its swing: dict of that cycle's period, theta_p2p, x_p2p, and the stretch's length."""
    period, swing, cart, tc = _cycles(out)
    change = np.abs(np.diff(swing)) / swing[:-1] + np.abs(np.diff(cart)) / cart[:-1]
    j = int(np.argmin(change))
    near = np.abs(swing / swing[j] - 1.0) < 0.01
    a = b = j
    while a > 0 and near[a - 1]:
        a -= 1
    while b + 1 < len(swing) and near[b + 1]:
        b += 1
    return {'period': period[j], 'theta_p2p': swing[j], 'x_p2p': cart[j], 'cycles': b - a + 1,
            'seconds': tc[b + 1] - tc[a]}


def test_both_sides_describe_the_same_loop(base, rig_edge):
    theta0 = math.radians(rig_edge[0])
    loop = _loop(base, theta0)
    M, m, g = RIG['M'], RIG['m'], RIG['g']
    assert loop.plant == pytest.approx((M, m, RIG['l'], g, RIG['alpha'], RIG['beta']), rel=1e-15)
    f = loop.friction
    assert f[fr.FP_MODEL] == fr.EXPONENTIAL and f[fr.FP_SMOOTH] == 1.0
    assert f[fr.FP_DELTA] == DELTA and f[fr.FP_GAMMA] == 2.0
    assert (f[fr.FP_EPS], f[fr.FP_MU_S], f[fr.FP_MU_C], f[fr.FP_V_S]) == pytest.approx(
        (RIG['eps'], RIG['mu_s'], RIG['mu_c'], RIG['v_s']), rel=1e-15)
    assert f[fr.FP_FN] == pytest.approx((M + m) * g, rel=1e-14)
    assert f[fr.FP_ASYM] == f[fr.FP_ASYM_V] == 0.0
    assert loop.extra_force[0] == loop.extra_force[1] == loop.extra_force[3] == 0.0   # no cogging, no offset
    assert loop.gain == GAIN
    a, dt, delay, vlimit = loop.control
    assert loop.dt == dt == RIG['Ts']
    assert a == pytest.approx(math.exp(-2 * math.pi * rs.FILTER_HZ * RIG['Ts']), rel=1e-14)
    assert delay == DELAY_SAMPLES and loop.switch == 0.0 and loop.delay == pytest.approx(DELAY, rel=1e-12)
    assert vlimit == rs.VMAX
    assert loop.resolution == (0.0, 0.0)                                # exact readings
    assert loop.sensors == (0.0, 0.0, 0.0) and loop.drive == (0.0, 0.0, 0.0)
    assert loop.limits[1] == rs.FALLEN
    # start (0, theta0, 0, 0); the delay buffer holds the first reading at rest, as rigsim's rows k < n
    assert tuple(loop.start[:4]) == (0.0, theta0, 0.0, 0.0)
    rows = loop.start[LS_HISTORY:LS_HISTORY + 4 * DELAY_SAMPLES].reshape(DELAY_SAMPLES, 4)
    assert (rows == (0.0, theta0, 0.0, 0.0)).all()
    truth = rig_edge[2]['settles']['truth']
    assert truth['controller']['K'] == list(GAIN) and truth['controller']['feedback_delay_samples'] == DELAY_SAMPLES
    assert truth['friction']['delta'] == DELTA and 'tanh' in truth['friction']['model']
    assert truth['encoder']['x_count_m'] == truth['encoder']['theta_count_rad'] == 0.0
    assert truth['sample_period_s'] == RIG['Ts'] and truth['substep_s'] == rs.SUBSTEP


def test_basin_edge_matches_the_independent_simulator(rig_edge, ipfric_edge):
    rig_lo, rig_hi, runs = rig_edge
    ipf_lo, ipf_hi, _ = ipfric_edge
    assert runs['falls']['truth']['end'] in ('fallen', 'track')
    rig_star, ipf_star = 0.5 * (rig_lo + rig_hi), 0.5 * (ipf_lo + ipf_hi)
    assert 0.083 < ipf_star < 0.085                                     # deg, as measured (0.0837744)
    assert rig_star == pytest.approx(ipf_star, rel=REL)


def test_threshold_run_lingers_on_the_unstable_orbit(rig_edge, orbit):
    assert not orbit.stable and orbit.largest_multiplier == pytest.approx(5.08, rel=0.01)
    for end in ('settles', 'falls'):
        cycle = _lingering(rig_edge[2][end])
        assert cycle['seconds'] > 5.0, end                              # lingers (measured 7.4-7.9 s)
        assert cycle['x_p2p'] == pytest.approx(orbit.x_p2p, rel=SWING_REL), end
        assert cycle['theta_p2p'] == pytest.approx(orbit.theta_p2p, rel=SWING_REL), end
        assert cycle['period'] == pytest.approx(orbit.period, rel=PERIOD_REL), end
