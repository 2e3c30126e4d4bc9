"""Periodic orbits found by shooting against what long runs of the same loop do."""
from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from ipfric_core.design.continuation import parse_continuation, trace, unstable_partners
from ipfric_core.design.orbit import find_orbit, loop_numbers, return_map, simulated_cycle
from ipfric_core.run.scenario import load_scenario


def exact(path, **controller):
    scn = load_scenario(path)
    return replace(scn, sim=replace(scn.sim, cart_resolution=0.0, angle_resolution=0.0),
                   controller=replace(scn.controller, **controller))


def loop_of(scn, delay=None):
    return loop_numbers(scn.make_rig().loop_spec(), scn.make_controller().loop_spec(), delay)


@pytest.mark.parametrize('config, controller', [
    ('config/fig7_old_gain_exponential.yaml', {}),                  # stick-slip limit cycle, sticking 41 %
    ('config/fig8_old_gain_dynamic.yaml', {'cutoff_hz': 0.0}),      # bristle friction, Figure 8
    ('config/delay_exponential_tau20ms.yaml', {}),                  # delay 20 ms: a fast large cycle
])
def test_orbit_matches_the_long_run(config, controller):
    scn = exact(config, **controller)
    orbit = find_orbit(loop_of(scn))
    sim = simulated_cycle(scn.make_rig(), scn.make_controller(), 120.0)
    assert orbit.stable and orbit.residual < 1e-8
    assert orbit.x_p2p == pytest.approx(sim['x_p2p_m'], rel=1e-3)
    assert orbit.theta_p2p == pytest.approx(sim['theta_p2p_rad'], rel=1e-3)
    assert orbit.period == pytest.approx(sim['period_s'], rel=1e-3)


def test_stick_slip_orbit_sticks_twice_and_contracts():
    orbit = find_orbit(loop_of(exact('config/fig7_old_gain_exponential.yaml')))
    assert orbit.sticks == 2 and 0.3 < orbit.stuck_fraction < 0.5
    # sticking forgets the cart's velocity: every multiplier but the phase's is tiny
    assert abs(orbit.multipliers[0]) < 1e-3


def test_an_unstable_orbit_is_found_and_is_unstable():
    # delay 60 ms (gain 15, exponential): a large stable cycle and a smaller unstable one
    scn = exact('config/fig7_old_gain_exponential.yaml')
    loop = loop_of(scn, 0.06)
    stable = find_orbit(loop)
    others = unstable_partners(loop, stable)
    assert stable.stable and others
    small = min(others, key=lambda o: o.x_p2p)
    assert not small.stable and abs(small.multipliers[0]) > 1.0
    assert small.x_p2p < stable.x_p2p
    # started on it, the loop stays near it for one period (it is an orbit) ...
    once = return_map(loop, small.state, small.level)
    assert once.x_p2p == pytest.approx(small.x_p2p, rel=1e-3)
    # ... and leaves it when nudged (it is unstable)
    z = small.state.copy()
    z[1] += 1e-6
    for _ in range(40):
        c = return_map(loop, z, small.level)
        if c.code != 'crossing':
            break
        z = c.state
    assert c.code != 'crossing' or abs(c.x_p2p - small.x_p2p) > 0.05 * small.x_p2p


def test_branch_over_a_few_delays_follows_the_orbit():
    scn = exact('config/fig7_old_gain_exponential.yaml')
    points, _ = trace(lambda tau: loop_of(scn, tau), [0.0, 0.001, 0.0015, 0.002], partners=False)
    first = [p for p in points if p.branch == 0]
    assert [p.parameter for p in first] == [0.0, 0.001, 0.0015, 0.002]   # 1.5 ms: between samples
    for p in first[1:]:
        sim_scn = replace(scn, controller=replace(scn.controller, delay=p.parameter)) \
            if abs(p.parameter / 0.001 - round(p.parameter / 0.001)) < 1e-9 else None
        if sim_scn is not None:
            sim = simulated_cycle(sim_scn.make_rig(), sim_scn.make_controller(), 120.0)
            assert p.orbit.x_p2p == pytest.approx(sim['x_p2p_m'], rel=1e-3)
    # the sub-sample delay lies between its neighbours
    x = [p.orbit.x_p2p for p in first]
    assert min(x[1], x[3]) - 1e-6 <= x[2] <= max(x[1], x[3]) + 1e-6


def test_parse_continuation():
    assert parse_continuation('delay=0:0.1:3') == ('delay', [0.0, 0.05, 0.1])
    assert parse_continuation('gain=1,1.2') == ('gain', [1.0, 1.2])
    with pytest.raises(ValueError, match='START:STOP'):
        parse_continuation('delay=0:0.1:1')


def cli(*args):
    return subprocess.run([sys.executable, '-m', 'ipfric_core.cli', 'orbit', *args], capture_output=True, text=True,
                          timeout=600)


def test_cli_refuses_an_unknown_parameter(tmp_path):
    r = cli('--continue', 'mass=1:2', '--out', str(tmp_path))
    assert r.returncode == 2
    assert "'mass'" in r.stderr and 'delay, gain, friction' in r.stderr


def test_cli_writes_orbit_branch_and_diagram(tmp_path):
    r = cli('--config', 'config/fig7_old_gain_exponential.yaml', '--continue', 'gain=1,1.05', '--simulate', '60',
            '--out', str(tmp_path), '--json')
    assert r.returncode == 0, r.stderr
    res = json.loads(r.stdout)
    o, s = res['orbits'][0], res['simulation']
    assert o['stable'] and o['x_p2p_m'] == pytest.approx(s['x_p2p_m'], rel=1e-3)
    rows = (tmp_path / 'branches.csv').read_text().splitlines()
    assert len(rows) >= 3 and rows[0].startswith('parameter,branch,x_p2p_m')
    assert (tmp_path / 'bifurcation.png').stat().st_size > 10_000
    assert np.isfinite(o['period_s'])
