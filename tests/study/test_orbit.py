"""Periodic orbits found by shooting against what long runs of the same loop do."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from ipfric_core.cli import main
from ipfric_core.run.scenario import load_scenario
from ipfric_core.study.continuation import parse_continuation, trace, unstable_partners
from ipfric_core.study.orbit import find_orbit, loop_numbers, return_map, simulated_cycle
from ipfric_core.study.variants import exact_sensors


def exact(path, **controller):
    scn = load_scenario(path)
    return replace(exact_sensors(scn), controller=replace(scn.controller, **controller))


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


def test_branch_over_delays_follows_the_stick_slip_orbit():
    scn = exact('config/fig7_old_gain_exponential.yaml')
    found = trace(lambda tau: loop_of(scn, tau), 0.0, 0.012, points=8, probes=1, partners=False)
    branch = [p for p in found.points if p.branch == 0]
    taus = [p.parameter for p in branch]
    assert taus[0] == 0.0 and taus[-1] == pytest.approx(0.012) and taus == sorted(taus)
    assert any(abs(t / 0.001 - round(t / 0.001)) > 0.05 for t in taus)           # delays between samples
    assert {e['event'] for e in found.events} == {'range'}
    assert all(p.orbit.stable and p.orbit.sticks == 2 for p in branch)
    # each point is the orbit itself: Newton from the loop's own cycle at that delay finds it again
    mid = branch[len(branch) // 2]
    again = find_orbit(loop_of(scn, mid.parameter))
    assert mid.orbit.x_p2p == pytest.approx(again.x_p2p, rel=1e-4)
    assert mid.orbit.period == pytest.approx(again.period, rel=1e-4)
    # and the end point is the cycle of a long run at 12 ms
    at = replace(scn, controller=replace(scn.controller, delay=0.012))
    sim = simulated_cycle(at.make_rig(), at.make_controller(), 120.0)
    assert branch[-1].orbit.x_p2p == pytest.approx(sim['x_p2p_m'], rel=1e-3)
    assert branch[-1].orbit.period == pytest.approx(sim['period_s'], rel=1e-3)
    # the period grows with the delay (5.41 s at 0, 5.53 s at 12 ms)
    assert branch[-1].orbit.period - branch[0].orbit.period == pytest.approx(0.122, abs=0.01)


def test_branch_of_the_large_cycle_grows_with_the_delay():
    # from 45 ms the loop runs a large cycle without sticking (Figure 7's gain): 5.3 cm at 45 ms
    scn = exact('config/fig7_old_gain_exponential.yaml')
    found = trace(lambda tau: loop_of(scn, tau), 0.045, 0.06, points=5, probes=1, partners=False)
    branch = [p for p in found.points if p.branch == 0]
    x = [p.orbit.x_p2p for p in branch]
    assert len(branch) >= 4 and all(b > a for a, b in zip(x, x[1:]))
    assert all(p.orbit.stable and p.orbit.stuck_fraction == 0.0 for p in branch)
    at = replace(scn, controller=replace(scn.controller, delay=0.06))
    sim = simulated_cycle(at.make_rig(), at.make_controller(), 60.0)
    assert branch[-1].orbit.x_p2p == pytest.approx(sim['x_p2p_m'], rel=1e-3)


def test_parse_continuation():
    assert parse_continuation('delay=0:0.1:3') == ('delay', 0.0, 0.1, 3)
    assert parse_continuation('gain=1:1.2') == ('gain', 1.0, 1.2, 100)
    for bad in ('delay=0:0.1:1', 'delay=0:0.1:2.5', 'delay=0.1:0.1', 'delay=0:nan', 'delay'):
        with pytest.raises(ValueError, match='START'):
            parse_continuation(bad)


def cli(*args):
    return subprocess.run([sys.executable, '-m', 'ipfric_core.cli', 'orbit', *args], capture_output=True, text=True,
                          timeout=600)


def test_cli_refuses_an_unknown_parameter(tmp_path):
    r = cli('--continue', 'mass=1:2', '--out', str(tmp_path))
    assert r.returncode == 2
    assert "'mass'" in r.stderr and 'delay, gain, friction' in r.stderr


def test_cli_writes_orbit_branch_and_diagram(tmp_path):
    r = cli('--config', 'config/fig7_old_gain_exponential.yaml', '--continue', 'gain=1:1.05:3', '--simulate', '60',
            '--out', str(tmp_path), '--json')
    assert r.returncode == 0, r.stderr
    res = json.loads(r.stdout)
    o, s = res['orbits'][0], res['simulation']
    assert o['stable'] and o['x_p2p_m'] == pytest.approx(s['x_p2p_m'], rel=1e-3)
    rows = (tmp_path / 'branches.csv').read_text().splitlines()
    assert len(rows) >= 3 and rows[0].startswith('parameter,branch,x_p2p_m')
    assert (tmp_path / 'bifurcation.png').stat().st_size > 10_000
    assert np.isfinite(o['period_s'])


@pytest.mark.parametrize('args, words', [
    (['--continue', 'delay=0:0.02:1000000000'], ['--continue', 'POINTS 1000000000', '2 .. 2000']),
    (['--continue', 'friction=-1:1'], ['--continue', 'negative friction scale', '>= 0']),
    (['--continue', 'delay=0:50'], ['--continue', 'delays out of range', '[0, 10] s']),
    (['--delay', '1e9'], ['--delay', '1e+09', '[0, 10] s']),
    (['--simulate', '1e12'], ['--simulate', '1000000000000.0', '0 .. 2000 s', '2000000 samples']),
    (['--simulate', '-1'], ['--simulate', '-1.0', '0 .. 2000 s']),
    (['--basin', '0.001,0.05', '--duration', '1e9'], ['--duration', '2000 s']),
    (['--cutoff-hz', '1e9'], ['--cutoff-hz', '1e+09', '[0, 10000] Hz']),
])
def test_cli_refuses_out_of_range_options_before_any_work(args, words, tmp_path, capsys):
    assert main(['orbit', *args, '--out', str(tmp_path / 'o')]) == 2
    err = capsys.readouterr().err
    assert all(w in err for w in words), err
    assert 'Traceback' not in err and not (tmp_path / 'o').exists()


def test_cli_refuses_a_file_for_out_and_a_fifo_for_config(tmp_path, capsys):
    f = tmp_path / 'f'
    f.write_text('x')
    assert main(['orbit', '--out', str(f)]) == 2
    assert f'--out: {f} is a file; allowed: a directory (new or existing)' in capsys.readouterr().err
    fifo = tmp_path / 'fifo'
    os.mkfifo(fifo)
    assert main(['orbit', '--config', str(fifo), '--out', str(tmp_path / 'o')]) == 2
    assert f'{fifo}: not a regular file' in capsys.readouterr().err
