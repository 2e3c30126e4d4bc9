"""The edge of the upright's basin and the unstable periodic orbit that bounds it.

Where the upright is locally stable but a larger start makes the pendulum fall (or hunt on
a large cycle), the starts that settle and those that leave are separated by the stable
manifold of an unstable periodic orbit, when the loop has one. A run started on that edge
runs onto the orbit and stays near it, the longer the closer its start is to the edge
(a decade of closeness buys log(10) / log(multiplier) periods).

:func:`basin_edge` bisects the initial angle theta0 [rad] between a start that settles and
one that leaves (:func:`fate`, runs of the sampled loop), takes the passes of the run at the
edge that change least and solves the orbit there by shooting (:func:`orbit.shoot`).
:func:`shape_threshold` bisects starts of the orbit's own shape, rest + f (u - rest): the
orbit bounds the basin along its shape when the threshold f is 1.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .orbit import LoopNumbers, Orbit, OrbitError, return_map, shoot, shrunk

__all__ = ['Edge', 'basin_edge', 'shape_threshold']

#: a run has settled once its swing over a window is below this fraction of the first window's
SETTLED = 1e-4
#: a run has left once its swing over a window is this many times the first window's
GROWN = 20.0
#: window over which a run's swing is measured [s]
WINDOW = 0.5
#: passes of the run at the edge tried as starts for Newton (those that change least)
TRIES = 3

#: fate of a run
SETTLES, LEAVES = -1, 1


def fate(loop: LoopNumbers, z: np.ndarray | None = None, duration: float = 40.0, window: float = WINDOW) -> int:
    """Whether the loop from state ``z`` (default: its start) settles (:data:`SETTLES`: its swing
    falls to :data:`SETTLED` of the first window's, or after ``duration`` [s] is smaller than that)
    or leaves (:data:`LEAVES`: it falls, reaches the track's end, its swing grows
    :data:`GROWN`-fold or after ``duration`` is still as large as at first: it hunts). The swing
    is the larger of the cart's [m] and the angle's [rad] peak-to-peak over a ``window`` [s]."""
    z = loop.start.copy() if z is None else np.array(z, dtype=float)
    first, swing = -1.0, 0.0
    for _ in range(max(1, int(round(duration / window)))):
        c = return_map(loop, z, math.inf, 1, max_period=window)
        if c.code != 'no_crossing':
            return LEAVES
        z = c.state
        swing = max(c.x_p2p, c.theta_p2p)
        if first < 0.0:
            first = swing
            if swing == 0.0:
                return SETTLES
        elif swing < SETTLED * first:
            return SETTLES
        elif swing > GROWN * first:
            return LEAVES
    return LEAVES if swing >= first else SETTLES


@dataclass
class Edge:
    """What :func:`basin_edge` found: runs from theta0 <= ``settles_below`` [rad] settle, from
    ``leaves_from`` [rad] they leave; the orbit the run at the edge lingers on (None, with
    ``why``, when Newton finds none there), and the number of runs."""

    settles_below: float
    leaves_from: float
    runs: int
    orbit: Orbit | None
    why: str = ''

    def summary(self) -> dict:
        out: dict[str, object] = {'settles_below_rad': self.settles_below, 'leaves_from_rad': self.leaves_from,
                                  'runs': self.runs, 'orbit': self.orbit.summary() if self.orbit else None}
        if self.orbit:
            out['threshold_over_orbit_amplitude'] = self.settles_below / (0.5 * self.orbit.theta_p2p)
        else:
            out['no_orbit'] = self.why
        return out


def _bisect(settles: Callable[[float], int], lo: float, hi: float, rtol: float) -> tuple[float, float, int]:
    """Bisection of a start parameter between ``lo`` (settles) and ``hi`` (leaves), geometric
    while lo > 0, to hi - lo <= rtol hi: (lo, hi, runs)."""
    runs = 0
    while hi - lo > rtol * hi:
        mid = math.sqrt(lo * hi) if lo > 0 else 0.5 * hi
        runs += 1
        if settles(mid) == SETTLES:
            lo = mid
        else:
            hi = mid
    return lo, hi, runs


def _lingering(loop: LoopNumbers, passes: int = 60) -> list[tuple[float, np.ndarray, int, float]]:
    """Passes of the loop from its start through the middle of its swing over the first second:
    (change over the pass [scaled], state, samples, centre of the angle [rad]) for each, fewest change
    first."""
    z = loop.start.copy()
    c = return_map(loop, z, math.inf, 1, max_period=1.0)
    z, level = c.state, c.theta_center
    scale = np.array([1e-3, 1e-3, 1e-2, 1e-2])          # x [m], theta [rad], x' [m/s], theta' [rad/s]
    found = []
    for k in range(passes):
        c = return_map(loop, z, level, 1, min_period=0.05)
        if c.code != 'crossing':
            break
        if k > 0:                                        # the first pass starts off the section
            found.append((float(np.max(np.abs(c.state[:4] - z[:4]) / scale)), z.copy(), c.samples, c.theta_center))
        z = c.state
    return sorted(found, key=lambda f: f[0])


def basin_edge(loop_at: Callable[[float], LoopNumbers], lo: float, hi: float, rtol: float = 1e-10,
               duration: float = 40.0) -> Edge:
    """The edge between settling and leaving over the initial angle theta0 in [``lo``, ``hi``]
    [rad] (``loop_at(theta0)``: the loop started there), to a relative width ``rtol``, and the
    unstable orbit the run at the edge lingers on; ``duration`` [s]: longest run.

    Raises ValueError when the run from ``lo`` does not settle or the one from ``hi`` does not leave.
    """
    ends = [fate(loop_at(a), duration=duration) for a in (lo, hi)]
    if ends != [SETTLES, LEAVES]:
        words = {SETTLES: 'settles', LEAVES: 'leaves'}
        raise ValueError(f'theta0 = {lo:g} rad {words[ends[0]]} and {hi:g} rad {words[ends[1]]}: the bracket '
                         f'must go from a start that settles to one that leaves (in {duration:g} s)')
    lo, hi, runs = _bisect(lambda a: fate(loop_at(a), duration=duration), lo, hi, rtol)
    loop = loop_at(lo)
    why = 'the run at the edge makes no pass through the middle of its swing'
    for _, z, samples, centre in _lingering(loop)[:TRIES]:
        on = return_map(loop, z, centre, 1, min_period=0.25 * samples * loop.dt)
        try:
            o = shoot(loop, on.state, centre, 1, min_period=0.5 * samples * loop.dt)
        except OrbitError as exc:
            why = f'Newton from the run at the edge: {exc}'
            continue
        if o.stable:
            why = f'Newton from the run at the edge found a stable orbit (x p2p {o.x_p2p:.3g} m), not the edge'
            continue
        return Edge(lo, hi, runs + 2, o)
    return Edge(lo, hi, runs + 2, None, why)


def shape_threshold(loop: LoopNumbers, orbit: Orbit, lo: float = 0.5, hi: float = 1.5, rtol: float = 1e-4,
                    duration: float = 40.0) -> tuple[float, float]:
    """Bisection of the factor f of starts rest + f (u - rest) of the orbit's shape (u its state on
    the section, :func:`orbit.shrunk`): (largest f found to settle, smallest found to leave).

    Raises ValueError when f = ``lo`` does not settle or f = ``hi`` does not leave.
    """
    ends = [fate(loop, shrunk(loop, orbit, f), duration) for f in (lo, hi)]
    if ends != [SETTLES, LEAVES]:
        raise ValueError(f'starts of the orbit\'s shape at {lo:g} and {hi:g} times its size do not go from '
                         f'settling to leaving (fates {ends[0]}, {ends[1]})')
    f_lo, f_hi, _ = _bisect(lambda f: fate(loop, shrunk(loop, orbit, f), duration), lo, hi, rtol)
    return f_lo, f_hi
