"""Branches of periodic orbits over a parameter (the delay, a gain scale, a friction value).

Each point is a Newton solve of :func:`orbit.shoot` started from the previous point of the
same branch (the state carried over, its delay buffer resized when the delay passes a whole
sample). A branch ends where Newton finds no orbit near the previous one: at a fold, where
it meets another branch (its largest multiplier reached 1 there), or where the orbit dies
(its amplitude fell to zero or the loop no longer returns). At every parameter the loop is
also run from the scenario's start and its orbit solved, which picks up the branch the loop
actually lands on (a new branch id when it is not one being traced).
"""
from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from .orbit import LoopNumbers, Orbit, OrbitError, find_orbit, resized, shoot, shrunk

#: relative amplitude difference under which two orbits are the same
SAME = 0.02


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
                'max_multiplier_modulus': float(abs(o.multipliers[0])) if len(o.multipliers) else 0.0,
                'stuck_fraction': o.stuck_fraction, 'residual': o.residual}


def _same(a: Orbit, b: Orbit) -> bool:
    return abs(a.x_p2p - b.x_p2p) <= SAME * max(a.x_p2p, b.x_p2p) and \
        abs(a.theta_p2p - b.theta_p2p) <= SAME * max(a.theta_p2p, b.theta_p2p)


def carry(orbit: Orbit, old: LoopNumbers, new: LoopNumbers):
    """The orbit's section state fitted to the loop ``new``."""
    return resized(orbit.state, int(old.control[2]), int(new.control[2]))


#: shrink factors of a stable orbit tried as starts for unstable ones
SHRINK = (0.001, 0.003, 0.01, 0.03, 0.1, 0.3, 0.6)


def unstable_partners(loop: LoopNumbers, orbit: Orbit, factors=SHRINK) -> list[Orbit]:
    """Other orbits found by Newton from the orbit shrunk towards rest (unstable ones bound
    the basin of rest and of the orbit)."""
    found: list[Orbit] = []
    for f in factors:
        try:
            o = shoot(loop, shrunk(loop, orbit, f), orbit.level, orbit.crossings)
        except OrbitError:
            continue
        if o.x_p2p > 0 and not _same(o, orbit) and not any(_same(o, q) for q in found):
            found.append(o)
    return found


def trace(make_loop: Callable[[float], LoopNumbers], values: Sequence[float], partners: bool = True,
          progress: Callable[[int, int], None] | None = None) -> tuple[list[BranchPoint], list[dict]]:
    """Orbits at each parameter value: (points, events).

    ``make_loop(p)`` gives the loop at parameter p. Events mark where a branch ends
    (``fold`` when its largest multiplier was near 1, else ``lost``) and where a new one is
    found (``found``), with the parameter between the last two points.
    """
    points: list[BranchPoint] = []
    events: list[dict] = []
    live: dict[int, tuple[Orbit, LoopNumbers]] = {}
    next_id = 0
    for k, p in enumerate(values):
        loop = make_loop(p)
        here: list[Orbit] = []
        for b, (prev, old) in list(live.items()):
            try:
                o = shoot(loop, carry(prev, old, loop), prev.level, prev.crossings)
                if o.x_p2p < 1e-9 or (any(_same(o, q) for q in here)):
                    raise OrbitError('merged')
            except OrbitError:
                near_one = len(prev.multipliers) and abs(abs(prev.multipliers[0]) - 1.0) < 0.5
                events.append({'parameter': 0.5 * (p + values[k - 1]), 'branch': b,
                               'event': 'fold' if near_one else 'lost'})
                del live[b]
                continue
            live[b] = (o, loop)
            here.append(o)
            points.append(BranchPoint(p, b, o))
        try:
            landed = find_orbit(loop)
        except OrbitError:
            landed = None
        candidates = [landed] if landed is not None else []
        if partners and landed is not None and k == 0:
            candidates += unstable_partners(loop, landed)
        for o in candidates:
            if any(_same(o, q) for q in here):
                continue
            live[next_id] = (o, loop)
            here.append(o)
            points.append(BranchPoint(p, next_id, o))
            if k:
                events.append({'parameter': p, 'branch': next_id, 'event': 'found'})
            next_id += 1
        if progress:
            progress(k + 1, len(values))
    return points, events


def parse_continuation(text: str) -> tuple[str, list[float]]:
    """``name=start:stop[:count]`` or ``name=a,b,c`` -> (name, values)."""
    if '=' not in text:
        raise ValueError(f'--continue {text!r}: expected NAME=START:STOP[:COUNT], e.g. delay=0:0.14:141')
    name, spec = text.split('=', 1)
    try:
        if ':' in spec:
            parts = [float(v) for v in spec.split(':')]
            if len(parts) not in (2, 3):
                raise ValueError
            count = int(parts[2]) if len(parts) == 3 else 51
            if count < 2:
                raise ValueError
            vals = [parts[0] + (parts[1] - parts[0]) * i / (count - 1) for i in range(count)]
        else:
            vals = [float(v) for v in spec.split(',')]
    except ValueError:
        raise ValueError(f'--continue {text!r}: values must be START:STOP[:COUNT] (COUNT >= 2) or a,b,c') from None
    if not vals or not all(math.isfinite(v) for v in vals):
        raise ValueError(f'--continue {text!r}: values must be finite numbers')
    return name.strip(), vals
