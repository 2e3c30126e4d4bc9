"""The edge of the upright's basin: bisection of the initial angle and the unstable orbit on it.

Where the upright is locally stable but larger starts fall (the bistability window of section
5), the edge between the starts that settle and those that fall is the stable manifold of an
unstable periodic orbit. Measured (exact sensors, `./ipfric orbit --basin`):

| scenario | delay | threshold theta0 | orbit x p2p | theta p2p | period | multiplier |
| --- | --- | --- | --- | --- | --- | --- |
| gain (23), exponential, tanh(100 v) | 90 ms | 1.46214e-3 rad | 1.6456 mm | 3.5133e-3 rad | 0.49577 s | 5.08 |
| gain (25), dynamic | 70 ms | 7.8917e-3 rad | 11.261 mm | 2.4510e-2 rad | 0.47130 s | 15.4 |

Starts of the orbit's own shape, rest + f (orbit - rest), settle up to f = 0.99999 and fall
from f = 1.00006: the orbit bounds the basin to 1e-4 (the bisection's width), far inside the
5 % the size of an unstable orbit is asked to match the bisection threshold to. Along the
paper's starts (theta0, the rest at 0) the threshold is a fixed fraction of the orbit's
angle amplitude (0.83 with tanh for delays of 40-100 ms, 0.64-0.76 on the dynamic plant):
those starts are not of the orbit's shape, and they reach it after a transient.
"""
from __future__ import annotations

import json
import math
import subprocess
import sys
from dataclasses import replace

import pytest

from ipfric_core.study.basin import LEAVES, SETTLES, basin_edge, fate, shape_threshold
from ipfric_core.study.orbit import return_map
from ipfric_core.study.sweep import threshold_angle
from ipfric_core.study.variants import load_variant, loop_of

CASES = {
    'tanh': ('config/fig9_new_gain_exponential.yaml', 'tanh', 0.09),
    'dynamic': ('config/fig10_new_gain_dynamic.yaml', None, 0.07),
}


def loops(config, smoothing, delay, cutoff_hz=None):
    """theta0 [rad] -> the loop of ``config`` with exact sensors started there."""
    base = load_variant(config, 'exact', smoothing, cutoff_hz)
    return lambda theta0: loop_of(base, 'theta0', theta0, delay)


@pytest.fixture(scope='module')
def edges():
    out = {}
    for name, (config, smoothing, delay) in CASES.items():
        loop_at = loops(config, smoothing, delay)
        out[name] = loop_at, basin_edge(loop_at, math.radians(0.001), math.radians(2.0))
    return out


@pytest.mark.parametrize('name', list(CASES))
def test_the_unstable_orbit_at_the_edge_bounds_the_basin(edges, name):
    loop_at, edge = edges[name]
    o = edge.orbit
    assert o is not None, edge.why
    assert not o.stable and o.largest_multiplier > 1.5 and o.residual < 1e-8
    assert edge.leaves_from - edge.settles_below <= 1e-9 * edge.leaves_from
    f_lo, f_hi = shape_threshold(loop_at(edge.settles_below), o)
    assert f_lo < 1.0 < f_hi and f_hi - f_lo < 1e-3
    # the paper's starts are not of the orbit's shape: their threshold is below its amplitude
    assert 0.5 < edge.settles_below / (0.5 * o.theta_p2p) < 0.95


def test_the_tanh_edge_matches_the_measured_orbit(edges):
    _, edge = edges['tanh']
    o = edge.orbit
    assert edge.settles_below == pytest.approx(1.46214e-3, rel=1e-5)
    assert (o.x_p2p, o.theta_p2p, o.period) == pytest.approx((1.6456e-3, 3.5133e-3, 0.49577), rel=2e-4)


def test_the_run_at_the_edge_lingers_on_the_orbit(edges):
    """The run from the bisected threshold passes the orbit's section again and again with the
    orbit's size and period before it settles."""
    loop_at, edge = edges['tanh']
    o = edge.orbit
    loop = loop_at(edge.settles_below)
    z = return_map(loop, loop.start, math.inf, 1, max_period=2.0).state
    close = 0
    for _ in range(6):
        c = return_map(loop, z, o.level, 1, min_period=0.5 * o.period)
        z = c.state
        close += abs(c.x_p2p / o.x_p2p - 1) < 0.01 and abs(c.samples * loop.dt - o.period) < 2 * loop.dt
    assert close >= 4


def test_the_sweep_threshold_brackets_the_edge(edges):
    """`sweep --threshold` (its own classifier of 20 s windows) finds the same threshold."""
    config, smoothing, delay = CASES['tanh']
    scn = load_variant(config, 'exact', smoothing)
    base = replace(scn, controller=replace(scn.controller, delay=delay))
    res = threshold_angle(base, math.radians(0.05), math.radians(0.1), 40.0)
    edge = edges['tanh'][1]
    assert res['settles_below_rad'] <= edge.settles_below <= res['oscillates_from_rad']
    assert res['hi_class'] == 'fallen'


def test_figure_8b_edge_has_no_orbit_on_it():
    """Gain (15) on the dynamic plant, no delay (Figure 8(b)): starts settle up to about 3.1e-5
    rad and go to the stable cycle above, but the runs at the edge creep without swinging
    through the middle of a swing: no periodic orbit bounds that basin."""
    loop_at = loops('config/fig8_old_gain_dynamic.yaml', None, 0.0, cutoff_hz=0.0)
    assert fate(loop_at(1e-6), duration=80.0) == SETTLES and fate(loop_at(1e-3), duration=80.0) == LEAVES
    edge = basin_edge(loop_at, 1e-6, 1e-3, rtol=1e-6, duration=80.0)
    assert 3.0e-5 < edge.settles_below < 3.3e-5
    assert edge.orbit is None and 'no pass' in edge.why


def run_cli(*args):
    return subprocess.run([sys.executable, '-m', 'ipfric_core.cli', 'orbit', *args], capture_output=True, text=True,
                          timeout=300)


def test_orbit_basin_from_the_command_line(tmp_path):
    r = run_cli('--config', 'config/fig9_new_gain_exponential.yaml', '--smoothing', 'tanh', '--delay', '0.09',
                '--basin', '1e-4,0.03', '--simulate', '0', '--json', '--out', str(tmp_path))
    assert r.returncode == 0, r.stderr
    b = json.loads(r.stdout)['basin']
    assert b['settles_below_rad'] == pytest.approx(1.46214e-3, rel=1e-5)
    assert not b['orbit']['stable'] and b['shape_threshold'][0] < 1.0 < b['shape_threshold'][1]


@pytest.mark.parametrize('args, words', [
    (('--basin', '0.03,1e-4'), '--basin'),
    (('--basin', 'small,large'), '--basin'),
    (('--basin', '1e-5,2e-5'), 'must go from a start that settles'),
    (('--delay', '-0.01'), '--delay'),
    (('--delay', 'nan'), '--delay'),
])
def test_bad_basin_requests_exit_2(tmp_path, args, words):
    r = run_cli('--config', 'config/fig9_new_gain_exponential.yaml', '--smoothing', 'tanh', '--delay', '0.09',
                '--simulate', '0', '--out', str(tmp_path), *args)
    assert r.returncode == 2 and words in r.stderr, r.stderr
