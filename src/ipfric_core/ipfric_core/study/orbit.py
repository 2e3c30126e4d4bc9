"""Periodic orbits of the sampled closed loop, found directly by shooting (no long simulation).

The loop is the hybrid system the simulator runs: the plant with exact stick-slip between
samples, the encoders, the velocity filter, the delay buffer and the drive at the samples
(:mod:`ipfric_core.physics.closedloop`, the same compiled functions). Its state between
samples is the flat loop state. The Poincare section is the first sample at which the
pendulum angle has risen through a level (the middle of its swing); the return map P takes
the loop state there to the state at the next such sample, N samples later.

The orbit's period is not a whole number of samples, so the sampled loop never repeats
exactly: it returns shifted along its own motion by a fraction of a sample (and its
breakaways, which lock to the samples where the command jumps, make the sample clock's
phase a neutral direction). A periodic orbit is therefore solved as an orbit of an
autonomous system with unknown period: P(u) - u + s w = 0 with the phase condition
w . (u - u0) = 0, where w is the loop's motion per second at the section (one sample step);
Newton's method with a finite-difference Jacobian, bordered by w. The period is N dt + s.

Stability: the eigenvalues of DP (Floquet multipliers) without the one of the phase
direction (about 1); the orbit is stable when the others lie inside the unit circle.
Unstable orbits are found too: Newton converges to them from nearby guesses.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np

from ..physics.closedloop import (
    LS_APPLIED,
    LS_HELD,
    LS_HISTORY,
    LS_LAST,
    LS_MODE,
    LS_PLAY,
    LS_RATE,
    LS_TIME,
    controller_sample,
    drive_command,
    limit_code,
    loop_start,
    plant_segment,
    run_closed_loop,
)
from ..physics.compiled import compiled
from ..physics.controller import FeedbackSpec
from ..physics.friction import DYNAMIC, FP_MODEL

__all__ = ['LoopNumbers', 'loop_numbers', 'free_entries', 'entry_scale', 'return_map', 'motion', 'OrbitError',
           'Orbit', 'shoot', 'bordered', 'return_map_jacobian', 'finish_orbit', 'settle', 'find_orbit', 'shrunk',
           'resized', 'simulated_cycle']

#: what a cycle can end with
CYCLE_CODES = ('crossing', 'no_crossing', 'fallen', 'track_limit')
#: columns of the return map's Jacobian in one task on an executor
COLUMNS_PER_TASK = 8
#: entries of a cycle's summary (see :func:`_cycle`)
OUT = ('samples', 'x_min', 'x_max', 'th_min', 'th_max', 'stuck', 'sticks', 'code')


@dataclass(frozen=True)
class LoopNumbers:
    """The sampled loop as the compiled functions take it (SI units).

    ``switch`` [s] is the sub-sample part of the feedback delay (see ``plant_segment``);
    ``control[2]`` holds its whole samples.
    """

    plant: tuple
    friction: tuple
    extra_force: tuple
    substep: float
    dt: float
    resolution: tuple
    sensors: tuple
    drive: tuple
    gain: tuple
    control: tuple
    switch: float
    limits: tuple
    start: np.ndarray = field(repr=False, compare=False)

    @property
    def delay(self) -> float:
        """The feedback delay tau [s]."""
        return self.control[2] * self.dt + self.switch

    def args(self):
        return (self.plant, self.friction, self.extra_force, self.substep, self.dt, self.resolution,
                self.sensors, self.drive, self.gain, self.control, self.switch, self.limits)


def loop_numbers(rig_spec, feedback_spec, delay: float | None = None) -> LoopNumbers:
    """The loop of a fresh ``Rig.loop_spec()`` and ``StateFeedback.loop_spec()``.

    ``delay`` [s] replaces the controller's delay; it may fall between samples (its fraction
    of a sample delays the switch of the held voltage).
    """
    r, f = rig_spec, feedback_spec
    dt = float(f.control[1])
    control = tuple(f.control)
    switch = 0.0
    if delay is not None:
        if not (math.isfinite(delay) and delay >= 0.0):
            raise ValueError(f'delay = {delay!r} s: must be finite and >= 0')
        whole = math.floor(delay / dt + 1e-9)
        switch = max(0.0, delay - whole * dt)
        if switch < 1e-12:
            switch = 0.0
        control = (control[0], control[1], float(whole), control[3])
    start = loop_start(r, FeedbackSpec(gain=tuple(f.gain), control=control))
    return LoopNumbers(tuple(r.plant), tuple(r.friction), tuple(r.extra_force), float(r.substep), float(r.dt),
                       tuple(r.resolution), tuple(r.sensors), tuple(r.drive), tuple(f.gain), control, switch,
                       tuple(r.limits), start)


@compiled
def _cycle(pp, fp, ef, substep, dt, resolution, sensors, drive, gain, control, switch, limits,
           z, level, min_samples, max_samples, out):
    """Run loop state ``z`` (at a sample, in place) to the next sample at which theta has risen
    through ``level`` [rad] since the previous one, ``min_samples`` on at the earliest.

    ``out`` receives :data:`OUT`: samples N, extremes of the true x [m] and theta [rad] at the
    samples, samples stuck, sticking phases, code = index in :data:`CYCLE_CODES`.
    """
    x_min = x_max = z[0]
    th_min = th_max = z[1]
    stuck, sticks, code = 0.0, 0.0, 1.0
    n = 0
    while n < max_samples:
        limit = limit_code(z, limits)
        if limit:
            code = 1.0 + limit
            break
        x_min, x_max = min(x_min, z[0]), max(x_max, z[0])
        th_min, th_max = min(th_min, z[1]), max(th_max, z[1])
        was_stuck, before = z[LS_MODE] != 0.0, z[1]
        _, _, v = controller_sample(resolution, sensors, gain, control, z)
        drive_command(drive, control, z, v)
        plant_segment(pp, fp, ef, substep, z, 0.0, dt, switch)
        n += 1
        if z[LS_MODE] != 0.0:
            stuck += 1.0
            if not was_stuck:
                sticks += 1.0
        if before < level <= z[1] and n >= min_samples:
            code = 0.0
            break
    out[0], out[1], out[2], out[3], out[4] = n, x_min, x_max, th_min, th_max
    out[5], out[6], out[7] = stuck, sticks, code


@compiled(parallel=True)
def _cycles_apart(pp, fp, ef, substep, dt, resolution, sensors, drive, gain, control, switch, limits,
                  z, moved, steps, level, crossings, min_samples, max_samples, ends, codes):
    """``crossings`` passes of :func:`_cycle` from ``z`` with entry ``moved[j]`` moved by
    ``steps[j]``, for every j (on every core): end states in ``ends[j]``, codes in ``codes[j]``."""
    for j in numba.prange(len(moved)):
        zj = z.copy()
        zj[moved[j]] += steps[j]
        out = np.zeros(len(OUT))
        for _ in range(crossings):
            _cycle(pp, fp, ef, substep, dt, resolution, sensors, drive, gain, control, switch, limits,
                   zj, level, min_samples, max_samples, out)
            if out[7] != 0.0:
                break
        ends[j, :] = zj
        codes[j] = out[7]


def free_entries(loop: LoopNumbers, n: int) -> np.ndarray:
    """Indices of the loop state an orbit solves for: all but the mode, the clock and entries
    the loop never changes (a bristle state without the dynamic law, an encoder play of 0, the
    voltage before a sub-sample switch without one)."""
    inert = {LS_MODE, LS_MODE + 1, LS_MODE + 2, LS_TIME}
    if loop.friction[FP_MODEL] != DYNAMIC:
        inert.add(4)
    if loop.sensors[2] <= 0.0:
        inert.add(LS_PLAY)
    if loop.switch <= 0.0:
        inert.add(LS_HELD)
    return np.array([i for i in range(n) if i not in inert])


def entry_scale(loop: LoopNumbers, n: int) -> np.ndarray:
    """Typical size of each free entry, for finite-difference steps and norms."""
    s = np.full(n, 1e-3)                       # positions [m], angles [rad], z [m]
    s[2] = s[3] = 1e-2                         # velocities [m/s, rad/s]
    s[LS_APPLIED:LS_APPLIED + 2] = 1e-2        # voltages [V]
    s[LS_RATE:LS_RATE + 2] = 1e-2
    return s[free_entries(loop, n)]


@dataclass
class Cycle:
    """One pass of the return map (``crossings`` returns to the section)."""

    state: np.ndarray
    samples: int
    x_p2p: float
    theta_p2p: float
    x_center: float
    theta_center: float
    stuck_fraction: float
    sticks: int
    code: str


def return_map(loop: LoopNumbers, z: np.ndarray, level: float, crossings: int = 1,
               max_period: float = 60.0, min_period: float = 0.0) -> Cycle:
    """P^crossings from loop state ``z`` (at a sample), the section being theta rising
    through ``level`` [rad]; one pass ends after ``max_period`` [s] without a return, and
    returns no sooner than ``min_period`` [s] (a start just below the level does not count
    the crossing right after it)."""
    z = np.array(z, dtype=float)
    out = np.zeros(len(OUT))
    n = stuck = sticks = 0
    lo, hi = np.array([np.inf, np.inf]), np.array([-np.inf, -np.inf])
    max_samples = int(max_period / loop.dt)
    code = 'crossing'
    for _ in range(crossings):
        _cycle(*loop.args(), z, level, int(min_period / loop.dt), max_samples, out)
        code = CYCLE_CODES[int(out[7])]
        n += int(out[0])
        stuck += int(out[5])
        sticks += int(out[6])
        lo = np.minimum(lo, out[[1, 3]])
        hi = np.maximum(hi, out[[2, 4]])
        if code != 'crossing':
            break
    return Cycle(z, n, hi[0] - lo[0], hi[1] - lo[1], 0.5 * (hi[0] + lo[0]), 0.5 * (hi[1] + lo[1]),
                 stuck / max(n, 1), sticks, code)


def motion(loop: LoopNumbers, z: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """The loop's motion at state ``z`` on the entries ``idx`` [per s]: one sample step over dt."""
    after = np.array(z, dtype=float)
    _cycle(*loop.args(), after, math.inf, 0, 1, np.zeros(len(OUT)))
    return (after[idx] - z[idx]) / loop.dt


class OrbitError(RuntimeError):
    """No periodic orbit where one was looked for."""


@dataclass
class Orbit:
    """A periodic orbit of the sampled loop.

    x_p2p [m], theta_p2p [rad], period [s] (N dt + s), stuck_fraction (of the period),
    sticks (sticking phases per period), multipliers (Floquet, the phase direction's left
    out, largest modulus first), residual (scaled max |P(u) - u + s w|), state (loop state at
    the section), level [rad] of the section.
    """

    x_p2p: float
    theta_p2p: float
    period: float
    x_center: float
    stuck_fraction: float
    sticks: int
    crossings: int
    multipliers: np.ndarray
    residual: float
    iterations: int
    state: np.ndarray = field(repr=False)
    level: float = 0.0

    @property
    def largest_multiplier(self) -> float:
        """Modulus of the largest Floquet multiplier (0 without any)."""
        return float(abs(self.multipliers[0])) if len(self.multipliers) else 0.0

    @property
    def stable(self) -> bool:
        return self.largest_multiplier < 1.0

    def summary(self) -> dict:
        m = self.multipliers[:4]
        return {'x_p2p_m': float(self.x_p2p), 'theta_p2p_rad': float(self.theta_p2p), 'period_s': float(self.period),
                'x_center_m': float(self.x_center), 'stuck_fraction': float(self.stuck_fraction),
                'sticks_per_period': int(self.sticks), 'crossings_per_period': int(self.crossings),
                'stable': self.stable, 'multipliers': [[float(v.real), float(v.imag)] for v in m],
                'max_multiplier_modulus': self.largest_multiplier,
                'residual': float(self.residual), 'newton_iterations': int(self.iterations)}


def _residual(loop, z, level, crossings, idx, scale, w, s, min_period):
    c = return_map(loop, z, level, crossings, min_period=min_period)
    if c.code != 'crossing':
        what = 'falls' if c.code == 'fallen' else c.code.replace('_', ' ')
        raise OrbitError(f'no return to the section: the loop {what}')
    return c, (c.state[idx] - z[idx] + s * w) / scale


def shoot(loop: LoopNumbers, z: np.ndarray, level: float, crossings: int = 1, tol: float = 1e-9,
          max_iter: int = 25, min_period: float = 0.0, executor=None) -> Orbit:
    """Newton's method on P^m(u) - u + s w = 0, w . (u - u0) = 0 from loop state ``z`` (at a
    sample on the section of theta rising through ``level`` [rad]); ``executor`` as
    :func:`return_map_jacobian` takes it."""
    z = np.array(z, dtype=float)
    idx, scale = free_entries(loop, len(z)), entry_scale(loop, len(z))
    n = len(idx)
    w = motion(loop, z, idx)
    s = 0.0
    res = math.inf
    for it in range(1, max_iter + 1):
        c, g = _residual(loop, z, level, crossings, idx, scale, w, s, min_period)
        res = float(np.max(np.abs(g)))
        J = return_map_jacobian(loop, z, level, crossings, idx, scale, c.state[idx], min_period=min_period,
                                executor=executor)
        if res < tol:
            return finish_orbit(loop, z, level, crossings, c, J, w, s, res, it)
        A = bordered(J, w / scale, np.zeros(n))[:, :n + 1]          # p held: no parameter column
        step = np.linalg.lstsq(A, np.concatenate([-g, [0.0]]), rcond=None)[0]
        du, ds = step[:n] * scale, step[n]
        lam = 1.0
        for _ in range(12):           # damped: the first step that lowers the residual
            zt = z.copy()
            zt[idx] += lam * du
            try:
                _, gt = _residual(loop, zt, level, crossings, idx, scale, w, s + lam * ds, min_period)
            except OrbitError:
                gt = np.array([math.inf])
            if np.max(np.abs(gt)) < res:
                break
            lam *= 0.5
        else:
            raise OrbitError(f'Newton stalled at residual {res:.3g} (iteration {it})')
        z, s = zt, s + lam * ds
    raise OrbitError(f'Newton did not converge in {max_iter} iterations (residual {res:.3g})')


def bordered(J: np.ndarray, w: np.ndarray, col: np.ndarray) -> np.ndarray:
    """[[J - I, w, dP/dq], [w / |w|, 0, 0]]: the orbit equations' Jacobian in (v, s, q) (scaled
    free entries, phase shift [s], parameter) with the phase condition, (n + 1) x (n + 2)."""
    n = len(w)
    A = np.zeros((n + 1, n + 2))
    A[:n, :n] = J - np.eye(n)
    A[:n, n], A[:n, n + 1] = w, col
    A[n, :n] = w / max(np.linalg.norm(w), 1e-300)
    return A


def passes_apart(loop: LoopNumbers, z: np.ndarray, moved: np.ndarray, steps: np.ndarray, level: float,
                 crossings: int, min_samples: int, max_samples: int) -> tuple[np.ndarray, np.ndarray]:
    """(end states, codes) of ``crossings`` passes of the return map from ``z`` with entry
    ``moved[j]`` moved by ``steps[j]``, for every j, on this process's cores."""
    ends, codes = np.empty((len(moved), len(z))), np.empty(len(moved))
    _cycles_apart(*loop.args(), z, moved, steps, level, crossings, min_samples, max_samples, ends, codes)
    return ends, codes


def return_map_jacobian(loop, z, level, crossings, idx, scale, base, max_period: float = 60.0, min_period: float = 0.0,
                        executor=None):
    """Finite-difference D(P^m) on the free entries, in scaled units (forward differences, the
    columns on every core, or with ``executor`` (a ``concurrent.futures`` executor, e.g. a Dask
    cluster's) in tasks of :data:`COLUMNS_PER_TASK` columns: the same numbers either way)."""
    steps = 1e-7 * np.maximum(np.abs(z[idx]), scale)
    bounds = (level, crossings, int(min_period / loop.dt), int(max_period / loop.dt))
    if executor is None:
        ends, codes = passes_apart(loop, z, idx, steps, *bounds)
    else:
        tasks = [executor.submit(passes_apart, loop, z, idx[k:k + COLUMNS_PER_TASK], steps[k:k + COLUMNS_PER_TASK],
                                 *bounds) for k in range(0, len(idx), COLUMNS_PER_TASK)]
        parts = [t.result() for t in tasks]
        ends, codes = np.vstack([e for e, _ in parts]), np.concatenate([c for _, c in parts])
    if np.any(codes != 0.0):
        bad = CYCLE_CODES[int(codes[np.flatnonzero(codes)[0]])]
        raise OrbitError(f'the return map is not defined next to this state ({bad.replace("_", " ")})')
    return (ends[:, idx] - base).T / scale[:, None] * (scale / steps)[None, :]


def finish_orbit(loop, z, level, crossings, c, J, w, s, res, it) -> Orbit:
    vals, vecs = np.linalg.eig(J)
    wn = w / entry_scale(loop, len(z))
    wn = wn / max(np.linalg.norm(wn), 1e-300)
    align = np.abs(np.conj(vecs.T) @ wn) / np.maximum(np.linalg.norm(vecs, axis=0), 1e-300)
    phase = int(np.argmax(align - np.abs(vals - 1.0)))  # the phase direction: along w, about 1
    mult = np.delete(vals, phase)
    mult = mult[np.argsort(-np.abs(mult))]
    return Orbit(c.x_p2p, c.theta_p2p, c.samples * loop.dt + s, c.x_center, c.stuck_fraction, c.sticks, crossings,
                 mult, res, it, z.copy(), level)


def settle(loop: LoopNumbers, z: np.ndarray | None = None, transient: float = 30.0, cycles: int = 6):
    """Run the loop from ``z`` (default: its start) for ``transient`` [s], take the middle of
    the angle's swing over the last third as the section's level, then pass ``cycles``
    returns to it.

    Returns (loop state, level [rad], list of Cycles); state None when the loop stops
    oscillating (it settles or falls).
    """
    z = loop.start.copy() if z is None else np.array(z, dtype=float)
    first = return_map(loop, z, math.inf, 1, 2 * transient / 3)
    last = return_map(loop, first.state, math.inf, 1, transient / 3)
    if last.code != 'no_crossing' or not last.theta_p2p > 1e-9:
        return None, math.nan, [last]
    level = last.theta_center
    seen = [return_map(loop, last.state, level)]
    while len(seen) < cycles and seen[-1].code == 'crossing':
        seen.append(return_map(loop, seen[-1].state, level))
    if seen[-1].code != 'crossing':
        return None, math.nan, seen
    return seen[-1].state, level, seen


def find_orbit(loop: LoopNumbers, z: np.ndarray | None = None, transient: float = 30.0,
               tol: float = 1e-9) -> Orbit:
    """The periodic orbit the loop runs into from ``z`` (default: the scenario's start)."""
    state, level, seen = settle(loop, z, transient)
    if state is None:
        raise OrbitError(f'the loop does not keep oscillating from this start (it '
                         f'{"falls" if seen[-1].code == "fallen" else "settles"})')
    why = None
    for m in range(1, 5):               # crossings of the section per period
        try:
            return shoot(loop, state, level, m, tol)
        except OrbitError as exc:
            why = exc
    raise OrbitError(f'no periodic orbit with 1-4 crossings of the section: {why}')


def _x_entries(n: int, delay: int) -> list[int]:
    """Indices of cart positions in a loop state of length ``n``."""
    return [0, LS_PLAY, LS_LAST] + [LS_HISTORY + 4 * i for i in range(delay)]


def shrunk(loop: LoopNumbers, orbit: Orbit, factor: float) -> np.ndarray:
    """The orbit's section state shrunk by ``factor`` towards rest at its centre: a start
    for a smaller orbit (an unstable one between rest and the orbit)."""
    z = orbit.state
    rest = np.zeros(len(z))
    rest[_x_entries(len(z), int(loop.control[2]))] = orbit.x_center
    g = rest + factor * (z - rest)
    g[LS_MODE:LS_MODE + 3] = z[LS_MODE:LS_MODE + 3]
    g[LS_TIME] = z[LS_TIME]
    return g


def resized(z: np.ndarray, delay_from: int, delay_to: int) -> np.ndarray:
    """Loop state ``z`` with ``delay_from`` history rows carried to ``delay_to`` rows (rows
    older than the oldest extrapolated linearly from the two oldest, or the oldest rows dropped)."""
    if delay_from == delay_to:
        return z.copy()
    rows = z[LS_HISTORY:LS_HISTORY + 4 * delay_from].reshape(delay_from, 4)
    if delay_to > delay_from:
        if delay_from > 1:                 # the readings before the oldest, extrapolated in time
            back = np.arange(delay_to - delay_from, 0, -1)[:, None]
            older = rows[:1] - back * (rows[1:2] - rows[:1])
        else:
            first = rows[:1] if delay_from else z[[LS_LAST, LS_LAST + 1, LS_RATE, LS_RATE + 1]][None, :]
            older = np.repeat(first, delay_to - delay_from, axis=0)
        rows = np.vstack([older, rows])
    else:
        rows = rows[delay_from - delay_to:]
    return np.concatenate([z[:LS_HISTORY], rows.ravel(), z[LS_HISTORY + 4 * delay_from:]])


def simulated_cycle(rig, controller, duration: float) -> dict:
    """What a plain run does: cart and angle peak-to-peak over its last half (true states) and
    the mean period between rises of theta through the middle of its swing [s]."""
    tr = run_closed_loop(rig, controller, duration)
    half = len(tr.t) // 2
    th = tr.state[half:, 1]
    lvl = 0.5 * (th.max() + th.min())
    up = np.flatnonzero((th[:-1] < lvl) & (th[1:] >= lvl))
    period = float((up[-1] - up[0]) / (len(up) - 1) * rig.dt) if len(up) > 1 else math.nan
    return {'x_p2p_m': float(np.ptp(tr.state[half:, 0])), 'theta_p2p_rad': float(np.ptp(th)), 'period_s': period,
            'end_reason': tr.end_reason, 'duration_s': duration}
