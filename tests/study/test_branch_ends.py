"""How branches of orbits end: folds where a stable and an unstable orbit meet, and the Hopf
point where an unstable orbit shrinks into the upright.

Measured (exact sensors):
- Figure 7's gain, large cycle: its amplitude climbs to 31 cm and the branch turns back at a
  fold at 83.29 ms (20-point budget over 78-86 ms; the largest multiplier passes +1 at
  83.24 ms) and goes on as a larger unstable cycle. Runs from the scenario's start fall from
  83.1 ms (`design --check`): near the fold the stable cycle's basin shrinks to nothing.
- Gain (23), tanh(100 v): the unstable orbit on the basin's edge (`basin_edge` at 100 ms,
  1.19 mm) shrinks as the delay grows and dies at 107.6566 ms (its squared amplitude
  extrapolated to 0). The sampled loop's own linearization at the upright (one sample of
  the loop, finite differences, its eigenvalues) has a complex pair crossing the unit circle
  at 107.6564 ms, at 1.569 Hz (0.637 s); the orbit's period there is 0.637 s. Its
  continuous-time tau_c of eq. (27) is 106.9 ms: the 1 kHz hold and the 20 Hz filter add
  0.75 ms.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from ipfric_core.study.basin import basin_edge
from ipfric_core.study.continuation import trace
from ipfric_core.study.orbit import free_entries, passes_apart, return_map
from ipfric_core.study.variants import load_variant, loop_of


def test_the_large_cycle_ends_in_a_fold_beside_where_runs_fall():
    base = load_variant('config/fig7_old_gain_exponential.yaml', 'exact', None)
    found = trace(lambda v: loop_of(base, 'delay', v), 0.078, 0.086, 20, probes=1, partners=False)
    folds = [e['parameter'] for e in found.events if e['event'] == 'fold']
    assert len(folds) == 1 and 0.0831 < folds[0] < 0.0835
    turn = [e for e in found.events if e['event'] == 'stability']
    assert turn and turn[0]['multiplier'] == '+1' and abs(turn[0]['parameter'] - folds[0]) < 3e-4
    # stable below the fold, unstable on the way back
    stable = [bp.orbit.x_p2p for bp in found.points if bp.orbit.stable]
    unstable = [bp.orbit.x_p2p for bp in found.points if not bp.orbit.stable]
    assert stable and unstable and min(unstable) > max(stable) * 0.9


def sampled_critical_delay(base, lo: float, hi: float) -> float:
    """Delay [s] at which the largest complex eigenvalue of one sample of the loop at the
    upright (finite differences) reaches the unit circle, by bisection."""
    def radius(delay):
        loop = loop_of(base, 'theta0', 0.0, delay)
        z = loop.start
        idx = free_entries(loop, len(z))
        ends, _ = passes_apart(loop, z, idx, np.full(len(idx), 1e-9), math.inf, 1, 0, 1)
        after = return_map(loop, z, math.inf, 1, max_period=1.5 * loop.dt).state
        vals = np.linalg.eigvals((ends[:, idx] - after[idx]).T / 1e-9)
        return np.max(np.abs(vals[np.abs(vals.imag) > 1e-9]))
    while hi - lo > 1e-7:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if radius(mid) < 1.0 else (lo, mid)
    return 0.5 * (lo + hi)


def test_the_edge_orbit_dies_at_the_sampled_loops_critical_delay():
    base = load_variant('config/fig9_new_gain_exponential.yaml', 'exact', 'tanh')
    edge = basin_edge(lambda a: loop_of(base, 'theta0', a, 0.1), 1e-4, 0.03)
    found = trace(lambda v: loop_of(base, 'delay', v), 0.1, 0.11, 40, probes=1, partners=False,
                  orbits=[(0.1, edge.orbit)])
    dies = [e['parameter'] for e in found.events if e['event'] == 'dies']
    assert len(dies) == 1
    assert not any(e['event'] == 'fold' for e in found.events)
    assert all(not bp.orbit.stable for bp in found.points)
    tau = sampled_critical_delay(base, 0.105, 0.110)
    assert tau == pytest.approx(0.107656, abs=2e-6)
    assert dies[0] == pytest.approx(tau, abs=2e-5)
