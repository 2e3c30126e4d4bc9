"""Branches of periodic orbits over a parameter (the delay, a gain scale, a friction scale),
traced by pseudo-arclength continuation.

A point of a branch is X = (u, s, p): the loop state u at the section, the phase shift s [s]
of :func:`orbit.shoot` and the parameter p. From a solved point the predictor steps along the
branch's tangent (the secant of its last two points; at a branch's start the null vector of
the bordered Jacobian), and the corrector solves P(u; p) - u + s w = 0, the phase condition
and <t, X - X_pred> = 0 by chord Newton (one finite-difference Jacobian, taken at the predicted
point, with the column dP/dp). Because p is an unknown, a branch goes round folds: where two
orbits meet and vanish, the branch turns back in p and goes on as the other orbit.

Norm: <X, Y> = (1/n) sum v_i y_i + q_x q_y, with v the free entries of u divided by their
typical sizes (:func:`orbit.entry_scale`), n their number, and q = p / (the range's length).
When the delay passes a whole sample the loop state gains or loses a row of the delay buffer;
predictor and tangent are carried over by :func:`orbit.resized`.

Events: ``fold`` (dp/ds changes sign), ``stability`` (the largest multiplier crosses the unit
circle: at +1, -1 or as a complex pair), and how a branch ends: ``range`` (the parameter
left the range), ``dies`` (the orbit shrinks to rest; where the corrector stops short of it,
at the parameter its squared amplitude extrapolates to 0, as at a Hopf point), ``joins`` (it runs onto another
branch), ``lost`` (the corrector fails at the smallest step), ``points`` (the point budget).
Besides the branch of the orbit the loop runs into at the range's start (and the unstable
orbits next to it), runs from the scenario's start at a few probe values pick up branches
the others do not reach.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from .orbit import (
    LoopNumbers,
    Orbit,
    OrbitError,
    bordered,
    entry_scale,
    find_orbit,
    finish_orbit,
    free_entries,
    motion,
    resized,
    return_map,
    return_map_jacobian,
    settle,
    shoot,
    shrunk,
)

__all__ = ['MAX_POINTS', 'unstable_partners', 'trace', 'parse_continuation']

#: relative amplitude difference under which two orbits are the same
SAME = 0.02
#: shrink factors of a stable orbit tried as starts for unstable ones
SHRINK = (0.001, 0.003, 0.01, 0.03, 0.1, 0.3, 0.6)
#: an orbit whose cart peak-to-peak falls below this [m] has died into rest
DEAD = 1e-6
#: below this largest multiplier modulus, passes of the loop refine a predicted state
CONTRACTING = 0.5
#: largest multiplier modulus range in which the Jacobian is retaken at the solved point
NEAR_CRITICAL = (0.7, 1.4)


@dataclass
class BranchPoint:
    """One orbit of a branch at a parameter value."""

    parameter: float
    branch: int
    orbit: Orbit

    def row(self) -> dict:
        o = self.orbit
        return {'parameter': self.parameter, 'branch': self.branch, 'x_p2p_m': o.x_p2p, 'theta_p2p_rad': o.theta_p2p,
                'period_s': o.period, 'stable': o.stable,
                'max_multiplier_modulus': o.largest_multiplier,
                'stuck_fraction': o.stuck_fraction, 'residual': o.residual}


@dataclass
class Branches:
    """What :func:`trace` found: the points (in order along each branch), the events, the
    probe runs and the number of corrector steps and Jacobians it took."""

    points: list[BranchPoint] = field(default_factory=list)
    events: list[dict] = field(default_factory=list)
    probes: list[dict] = field(default_factory=list)
    steps: int = 0
    jacobians: int = 0


def same_orbit(a: Orbit, b: Orbit) -> bool:
    """Whether two orbits have the same cart and angle peak-to-peak (within :data:`SAME`)."""
    return abs(a.x_p2p - b.x_p2p) <= SAME * max(a.x_p2p, b.x_p2p) and \
        abs(a.theta_p2p - b.theta_p2p) <= SAME * max(a.theta_p2p, b.theta_p2p)


def unstable_partners(loop: LoopNumbers, orbit: Orbit, factors=SHRINK) -> list[Orbit]:
    """Other orbits found by Newton from the orbit shrunk towards rest (unstable ones bound
    the basin of rest and of the orbit)."""
    found: list[Orbit] = []
    for f in factors:
        try:
            o = shoot(loop, shrunk(loop, orbit, f), orbit.level, orbit.crossings)
        except OrbitError:
            continue
        if o.x_p2p > 0 and not same_orbit(o, orbit) and not any(same_orbit(o, q) for q in found):
            found.append(o)
    return found


class _Window(OrbitError):
    """The corrector's parameter left the loop layout of the predicted point: p and the loop
    state where it did, a start for the corrector in the new layout."""

    def __init__(self, p: float, u: np.ndarray):
        super().__init__(f'the loop layout changes at {p:g}')
        self.p, self.u = p, u


@dataclass
class _Point:
    """A solved point: parameter p, its loop, the orbit, the unit tangent (tu full state
    length [state units], tq [range lengths]) along the branch and the length of the step
    that reached it (in the norm)."""

    p: float
    loop: LoopNumbers
    orbit: Orbit
    tu: np.ndarray
    tq: float
    step: float = 0.0


def _layout(loop: LoopNumbers) -> tuple[int, int]:
    return int(loop.control[2]), len(loop.start)


def _scaled(loop: LoopNumbers, n_state: int):
    idx = free_entries(loop, n_state)
    return idx, entry_scale(loop, n_state)


def _norm(tv: np.ndarray, tq: float) -> float:
    return math.sqrt(float(tv @ tv) / max(len(tv), 1) + tq * tq)


class _Tracer:
    """Continuation of one parameter: ``make_loop(p)``, range [lo, hi], ``budget`` points per
    branch at most, first step ``ds0`` (in the norm above)."""

    def __init__(self, make_loop, lo: float, hi: float, budget: int, ds0: float, tol: float = 1e-9,
                 growth: float = 4.0, executor=None):
        self.make_loop, self.lo, self.hi, self.budget, self.tol = make_loop, lo, hi, budget, tol
        self.executor = executor
        self.span = max(hi - lo, 1e-12)
        self.ds0, self.ds_min, self.ds_max = ds0, ds0 / 64, growth * ds0
        self.result = Branches()
        self.floor = 0.0       # a pass returns no sooner than this [s]: half the last orbit's

    # ------------------------------------------------------------------ pieces of a step
    def column(self, loop, p, u, level, crossings, end, idx, scale) -> np.ndarray:
        """dP/dq at (u, p), scaled (q = p / span); one-sided within p's loop layout."""
        h = 1e-6 * self.span
        for step in (h, -h):
            other = self.make_loop(p + step)
            if _layout(other) == _layout(loop):
                c = return_map(other, u, level, crossings, min_period=self.floor)
                if c.code == 'crossing':
                    return (c.state[idx] - end) / scale / (step / self.span)
        raise OrbitError('the return map is not defined next to this parameter')

    def loop_at(self, p: float) -> LoopNumbers:
        try:
            return self.make_loop(p)
        except ValueError as exc:          # a parameter the loop does not take (a negative delay)
            raise OrbitError(str(exc)) from None

    def derivatives(self, loop, p, u, level, crossings, idx, scale, column: bool = True):
        """(J, dP/dq) at (u, p): the Jacobian on the scaled free entries and the scaled
        parameter column (zeros without ``column``)."""
        base = return_map(loop, u, level, crossings, min_period=self.floor)
        if base.code != 'crossing':
            raise OrbitError(f'no return to the section ({base.code.replace("_", " ")})')
        J = return_map_jacobian(loop, u, level, crossings, idx, scale, base.state[idx], min_period=self.floor,
                                executor=self.executor)
        self.result.jacobians += 1
        if not column:
            return J, np.zeros(len(idx))
        return J, self.column(loop, p, u, level, crossings, base.state[idx], idx, scale)

    def correct(self, p_pred: float, u_pred: np.ndarray, level: float, crossings: int, tu, tq: float,
                fixed: bool = False, max_iter: int = 20, refreshes: int = 3, retake: bool = True):
        """Newton from the predicted point, the Jacobian kept while the residual falls fast and
        retaken (at most ``refreshes`` times) where it does not; returns (p, loop, orbit).
        ``fixed`` holds p at ``p_pred`` (a point on the range's bound) instead of the
        arclength condition."""
        loop = self.loop_at(p_pred)
        layout = _layout(loop)
        idx, scale = _scaled(loop, len(u_pred))
        n = len(idx)
        w = motion(loop, u_pred, idx) / scale
        wn = w / max(np.linalg.norm(w), 1e-300)
        tv = tu[idx] / scale
        v_pred, q_pred = u_pred[idx] / scale, (p_pred - self.lo) / self.span
        u, s, q = u_pred.copy(), 0.0, q_pred
        lu, J, taken, res_prev = None, None, 0, math.inf
        for it in range(1, max_iter + 1):
            p = self.lo + q * self.span
            here = loop if q == q_pred else self.loop_at(p)
            if _layout(here) != layout:
                raise _Window(p, u)
            c = return_map(here, u, level, crossings, min_period=self.floor)
            if c.code != 'crossing':
                raise OrbitError(f'no return to the section ({c.code.replace("_", " ")})')
            v = u[idx] / scale
            g = (c.state[idx] - u[idx]) / scale + s * w
            arc = q - q_pred if fixed else (tv @ (v - v_pred)) / n + tq * (q - q_pred)
            r = np.concatenate([g, [wn @ (v - v_pred), arc]])
            res = float(np.max(np.abs(g)))
            self.result.steps += 1
            if res < self.tol:
                if J is None:
                    J, _ = self.derivatives(here, p, u, level, crossings, idx, scale, column=False)
                orbit = finish_orbit(here, u, level, crossings, c, J, w * scale, s, res, it)
                if NEAR_CRITICAL[0] < orbit.largest_multiplier < NEAR_CRITICAL[1] and it > 1:   # J at the solution
                    J, _ = self.derivatives(here, p, u, level, crossings, idx, scale, column=False)
                    orbit = finish_orbit(here, u, level, crossings, c, J, w * scale, s, res, it)
                return p, here, orbit
            if lu is None or res > 0.5 * res_prev:
                if taken == refreshes or (res > 4.0 * res_prev and (taken > 1 or not retake)):   # diverging
                    raise OrbitError(f'the corrector stalled at residual {res:.3g}')
                J, col = self.derivatives(here, p, u, level, crossings, idx, scale, column=not fixed)
                taken += 1
                A = np.vstack([bordered(J, w, col), np.zeros(n + 2)])
                if fixed:
                    A[n + 1, n + 1] = 1.0
                else:
                    A[n + 1, :n], A[n + 1, n + 1] = tv / n, tq
                lu = scipy.linalg.lu_factor(A)
            res_prev = res
            d = scipy.linalg.lu_solve(lu, r)
            u[idx] -= d[:n] * scale
            s -= d[n]
            q -= d[n + 1]
        raise OrbitError(f'the corrector did not converge in {max_iter} steps')

    def tangent(self, loop, p, orbit, direction: float) -> tuple[np.ndarray, float]:
        """Unit tangent at a solved point: null vector of [[J - I, w, dP/dq], [w, 0, 0]],
        pointing to increasing p when ``direction`` > 0."""
        u = orbit.state
        idx, scale = _scaled(loop, len(u))
        J, col = self.derivatives(loop, p, u, orbit.level, orbit.crossings, idx, scale)
        w = motion(loop, u, idx) / scale
        n = len(idx)
        null = np.linalg.svd(bordered(J, w, col))[2][-1]
        tu = np.zeros(len(orbit.state))
        tu[idx] = null[:n] * scale
        tq = float(null[n + 1])
        k = _norm(null[:n], tq) * (1.0 if tq * direction >= 0 else -1.0)
        return tu / k, tq / k

    def secant(self, a: _Point, p: float, loop, orbit) -> _Point:
        """The new solved point with its unit tangent from point ``a``, orthogonal to the loop's
        motion (so that the section state does not drift along the orbit)."""
        u = orbit.state
        idx, scale = _scaled(loop, len(u))
        prev = resized(a.orbit.state, _layout(a.loop)[0], _layout(loop)[0])
        dv = (u[idx] - prev[idx]) / scale
        w = motion(loop, u, idx) / scale
        w /= max(np.linalg.norm(w), 1e-300)
        dv -= (dv @ w) * w
        dq = (p - a.p) / self.span
        k = _norm(dv, dq)
        if not k > 0:
            return _Point(p, loop, orbit, a.tu, a.tq, 0.0)
        tu = np.zeros(len(u))
        tu[idx] = dv / k * scale
        return _Point(p, loop, orbit, tu, dq / k, k)

    # ------------------------------------------------------------------ a branch
    def follow(self, start: _Point, branch: int, direction: float) -> list[BranchPoint]:
        """Points from ``start`` (excluded) in ``direction`` of p until the branch ends.

        Steps are in p (the state predicted along the secant, p held by the corrector) while
        that converges. Where a step in p fails (a fold ahead: no orbit at that p), they switch
        to pseudo-arclength at half the last step's length, go round the fold, and switch back
        once the branch runs along p again (its tangent as steep in p as where they switched,
        no real multiplier near +1)."""
        out: list[BranchPoint] = []
        events = self.result.events
        a, ds, dp = start, self.ds0, self.ds0 * self.span
        level, crossings = start.orbit.level, start.orbit.crossings
        end, failures, arc, tried, steep, reach = 'points', 0, False, False, 0.0, self.ds_max
        largest, before = start.orbit.x_p2p, None
        while len(out) < self.budget:
            self.floor = 0.5 * a.orbit.period / crossings
            if arc:
                p_pred = a.p + ds * a.tq * self.span
                u_pred = a.orbit.state + ds * a.tu
            else:
                p_pred = a.p + direction * dp
                u_pred = a.orbit.state + (p_pred - a.p) / (a.tq * self.span) * a.tu if abs(a.tq) > 0.05 \
                    else a.orbit.state.copy()
            last = not (self.lo <= p_pred <= self.hi)
            if last:
                p_pred = min(max(p_pred, self.lo), self.hi)
            orbit = self.solve(a, p_pred, u_pred, level, crossings, fixed=last or not arc, retake=failures == 0)
            if orbit is not None:
                b = self.secant(a, *orbit)
                if arc and b.step < 0.01 * ds:      # the corrector came back to the point it left
                    orbit = None
            if orbit is None:
                if not arc and not tried and a.step > 0:
                    arc, tried, steep, reach = True, True, abs(a.tq), max(a.step, self.ds_max)
                    ds = max(0.5 * a.step, self.ds_min)
                    continue
                failures += 1
                ds, dp = 0.5 * ds, 0.5 * dp
                if failures > 4 or ds < self.ds_min:
                    end = 'lost'
                    break
                continue
            p, loop, orbit = orbit
            failures, tried = 0, False
            out.append(BranchPoint(p, branch, orbit))
            largest = max(largest, orbit.x_p2p)
            if b.tq * a.tq < 0 and arc:
                if orbit.x_p2p > largest / 20:   # not the vertical stretch over a Hopf point
                    events.append({'parameter': _turning(before, a, b), 'branch': branch, 'event': 'fold'})
                direction = -direction
            if orbit.stable != a.orbit.stable:
                events.append({'parameter': 0.5 * (p + a.p), 'branch': branch, 'event': 'stability',
                               'multiplier': _crossing_kind(orbit if not orbit.stable else a.orbit)})
            before, a = a, b
            if orbit.x_p2p < DEAD:
                end = 'dies'
                break
            if self._joins(a, branch):
                end = 'joins'
                break
            if last or not (self.lo + 1e-9 * self.span < p < self.hi - 1e-9 * self.span):
                end = 'range'
                break
            if arc and not _near_one(orbit) and abs(a.tq) >= steep:
                arc = False                    # past the fold: steps in p again
            grow = 1.5 if orbit.iterations <= 4 else 1.0
            ds, dp = min(reach, ds * grow), min(self.ds_max * self.span, dp * grow)
        at = _rest_reached(out) if end == 'lost' else None
        if at is not None:
            end = 'dies'
        events.append({'parameter': a.p if at is None else at, 'branch': branch, 'event': end,
                       'x_p2p_m': a.orbit.x_p2p, 'max_multiplier_modulus': a.orbit.largest_multiplier})
        return out

    def solve(self, a: _Point, p_pred: float, u_pred: np.ndarray, level: float, crossings: int,
              fixed: bool, retake: bool = True):
        """(p, loop, orbit) from the predicted point, or None: the corrector, then (at a kink
        of the branch) damped Newton at the predicted p."""
        tu, held = a.tu, _layout(a.loop)[0]
        try:
            for _ in range(3):       # the corrector may cross into the next delay layout
                loop_pred = self.loop_at(p_pred)
                new = _layout(loop_pred)[0]
                u_pred, tu, held = resized(u_pred, held, new), resized(tu, held, new), new
                if fixed and a.orbit.largest_multiplier < CONTRACTING:   # the loop itself brings the state in
                    for _ in range(2):
                        c = return_map(loop_pred, u_pred, level, crossings, min_period=self.floor)
                        if c.code != 'crossing':
                            break
                        u_pred = c.state
                if u_pred[3] > 0.0:          # the section through the predicted state, half a sample back
                    level = u_pred[1] - 0.5 * loop_pred.dt * u_pred[3]
                try:
                    return self.correct(p_pred, u_pred, level, crossings, tu, a.tq, fixed=fixed, retake=retake)
                except _Window as jump:
                    p_pred, u_pred = jump.p, jump.u
        except OrbitError:
            pass
        if a.orbit.largest_multiplier >= 1.0:     # Newton alone only where the branch is stable
            return None
        try:
            loop = self.loop_at(p_pred)
            orbit = shoot(loop, resized(u_pred, held, _layout(loop)[0]), level, crossings, self.tol, 10, self.floor,
                          self.executor)
            self.result.jacobians += orbit.iterations
        except OrbitError:
            return None
        if abs(orbit.x_p2p - a.orbit.x_p2p) > 0.2 * a.orbit.x_p2p:
            return None                 # Newton went to another orbit
        return p_pred, loop, orbit

    def _joins(self, a: _Point, branch: int) -> bool:
        near = 0.01
        return any(bp.branch != branch and abs(bp.parameter - a.p) <= near * self.span and
                   same_orbit(bp.orbit, a.orbit) for bp in self.result.points)

    def add_branch(self, p: float, loop: LoopNumbers, orbit: Orbit) -> None:
        """Trace the branch through ``orbit`` at ``p`` both ways and keep its points in order."""
        branch = 1 + max((bp.branch for bp in self.result.points), default=-1)
        self.floor = 0.5 * orbit.period / orbit.crossings
        tu, tq = self.tangent(loop, p, orbit, 1.0)
        here = BranchPoint(p, branch, orbit)
        self.result.points.append(here)
        edge = 1e-9 * self.span
        back = self.follow(_Point(p, loop, orbit, -tu, -tq), branch, -1.0) if p > self.lo + edge else []
        ahead = self.follow(_Point(p, loop, orbit, tu, tq), branch, 1.0) if p < self.hi - edge else []
        self.result.points.remove(here)
        self.result.points.extend(back[::-1] + [here] + ahead)

    def covered(self, p: float, x_p2p: float) -> bool:
        """Whether a traced branch has an orbit of cart peak-to-peak ``x_p2p`` [m] near ``p``."""
        near = 0.03 * self.span
        return any(abs(bp.parameter - p) <= near and abs(bp.orbit.x_p2p - x_p2p) <= 0.05 * max(x_p2p, 1e-12)
                   for bp in self.result.points)


def _turning(before: _Point | None, a: _Point, b: _Point) -> float:
    """The parameter at a fold between solved points ``a`` and ``b`` (p turns back at ``b``):
    the vertex of the parabola p(arclength) through ``before``, ``a``, ``b`` (``b``'s p without
    ``before``)."""
    if before is None or not (a.step > 0 and b.step > 0):
        return b.p
    s = np.array([0.0, a.step, a.step + b.step])
    c2, c1, c0 = np.polyfit(s, [before.p, a.p, b.p], 2)
    if c2 == 0.0 or not 0.0 <= -c1 / (2 * c2) <= s[2]:
        return b.p
    return float(c0 - c1 * c1 / (4 * c2))


def _rest_reached(points: list[BranchPoint]) -> float | None:
    """Where a branch whose orbits shrink towards rest reaches it, or None: the parameter at which
    the squared cart amplitude of its last two points extrapolates to 0 (near a Hopf point the
    amplitude grows as the square root of the distance), when the last orbit is smaller than the
    one before and below 1/20 of the branch's largest."""
    if len(points) < 2:
        return None
    a, b = points[-2], points[-1]
    largest = max(bp.orbit.x_p2p for bp in points)
    if not (b.orbit.x_p2p < a.orbit.x_p2p and b.orbit.x_p2p < largest / 20):
        return None
    slope = (b.orbit.x_p2p ** 2 - a.orbit.x_p2p ** 2) / (b.parameter - a.parameter)
    return b.parameter - b.orbit.x_p2p ** 2 / slope


def _near_one(o: Orbit, within: float = 0.15) -> bool:
    """Whether a real multiplier of ``o`` lies within ``within`` of +1 (as at a fold)."""
    m = o.multipliers
    return bool(np.any((np.abs(np.imag(m)) < 1e-9) & (np.abs(np.real(m) - 1.0) < within)))


def _crossing_kind(unstable: Orbit) -> str:
    m = unstable.multipliers[0] if len(unstable.multipliers) else 0.0
    if abs(np.imag(m)) > 1e-6 * abs(m):
        return 'complex pair'
    return '+1' if np.real(m) > 0 else '-1'


def trace(make_loop: Callable[[float], LoopNumbers], start: float, stop: float, points: int = 100,
          probes: int = 6, partners: bool = True, tol: float = 1e-7, growth: float = 4.0,
          progress: Callable[[str], None] | None = None, executor=None,
          orbits: Sequence[tuple[float, Orbit]] = ()) -> Branches:
    """Branches of orbits for the parameter in [start, stop].

    ``make_loop(p)`` gives the loop at parameter p. The first step is 1/(``points`` - 1) of the
    range, so a smooth branch over the whole range takes about ``points`` points (at most
    ``points`` each way). Branches start from the orbit the loop runs into at ``start`` (and,
    with ``partners``, the unstable orbits found next to it), then from runs at ``probes``
    evenly spaced values whose cycles no traced branch holds. ``tol``: largest scaled residual
    of a point (1e-7: 0.1 um in a cart position). Steps grow up to ``growth`` times the first
    where the corrector converges fast (1: every step the first one). ``executor``: a
    ``concurrent.futures`` executor (a Dask cluster's) on which the Jacobians' columns run, in
    tasks (:func:`orbit.return_map_jacobian`); the branches are the same as without it.
    ``orbits``: (parameter, orbit) pairs found otherwise (an unstable orbit on a basin's edge)
    whose branches are traced first.
    """
    lo, hi = min(start, stop), max(start, stop)
    tr = _Tracer(make_loop, lo, hi, max(points, 2), 1.0 / (max(points, 2) - 1), tol, growth, executor)
    say = progress or (lambda text: None)
    for p, o in orbits:
        if lo <= p <= hi and not tr.covered(p, o.x_p2p):
            say(f'branch from a given orbit at {p:.4g}')
            try:
                tr.add_branch(p, make_loop(p), o)
            except OrbitError:
                continue
    grid = [lo + (hi - lo) * i / max(probes - 1, 1) for i in range(max(probes, 1))]
    for i, p in enumerate(grid):
        loop = make_loop(p)
        state, level, seen = settle(loop)
        probe = {'parameter': p, 'x_p2p_m': seen[-1].x_p2p if state is not None else 0.0,
                 'oscillates': state is not None}
        tr.result.probes.append(probe)
        if state is None or tr.covered(p, seen[-1].x_p2p):
            continue
        try:
            orbit = find_orbit(loop)
        except OrbitError:
            continue
        starts = [orbit] + (unstable_partners(loop, orbit) if partners and i == 0 else [])
        for o in starts:
            if not tr.covered(p, o.x_p2p):
                say(f'branch from {"the run" if o is orbit else "an unstable orbit"} at {p:.4g}')
                try:
                    tr.add_branch(p, loop, o)
                except OrbitError:
                    continue
                say(f'{len(tr.result.points)} points, {tr.result.jacobians} Jacobians')
    return tr.result


#: the most points ``--continue`` may ask for (each point solves an orbit: 2000 take hours already)
MAX_POINTS = 2000


def parse_continuation(text: str) -> tuple[str, float, float, int]:
    """``name=start:stop[:points]`` -> (name, start, stop, points); points default 100, at most
    :data:`MAX_POINTS`."""
    if '=' not in text:
        raise ValueError(f'--continue {text!r}: expected NAME=START:STOP[:POINTS], e.g. delay=0:0.14:100')
    name, spec = text.split('=', 1)
    try:
        parts = [float(v) for v in spec.split(':')]
        if len(parts) not in (2, 3):
            raise ValueError
        count = int(parts[2]) if len(parts) == 3 else 100
        if count < 2 or (len(parts) == 3 and parts[2] != count):
            raise ValueError
    except (ValueError, OverflowError):
        raise ValueError(f'--continue {text!r}: expected START:STOP[:POINTS] (POINTS a whole number >= 2)') from None
    if count > MAX_POINTS:
        raise ValueError(f'--continue {text!r}: POINTS {count} is too many; allowed: 2 .. {MAX_POINTS}')
    if not all(math.isfinite(v) for v in parts[:2]) or parts[0] == parts[1]:
        raise ValueError(f'--continue {text!r}: START and STOP must be finite and different')
    return name.strip(), parts[0], parts[1], count

