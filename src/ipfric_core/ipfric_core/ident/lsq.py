"""Bounded least squares of a simulation error whose Jacobian is costly.

A finite-difference Jacobian of the simulation error costs one simulation of every window
per parameter, and stick-slip makes the error only piecewise smooth, so its valleys are
crossed in many short steps. :func:`solve` drives ``scipy.optimize.least_squares``
(trust region reflective) with finite differences of the costly rows only (rows that are
linear in the parameters, the priors, come with their exact Jacobian) and ends a fit when a
step lowers the sum of squares by less than FTOL of it (a limit cycle's valley of Coulomb
level against viscous slope is flat to 1e-4: the fits crawled along it for hundreds of
simulations). The Jacobian is differenced afresh at every step: Broyden secant updates in
between lost precision on a ripple (0.84 counts left on the independent cart_cogging file
against 0.69) and saved no time once the fits stop at FTOL.

After a fit, :func:`rough`, :func:`quadratic` and :func:`scan_errors` check its standard errors
along each parameter.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

__all__ = ['solve', 'ROUGH_COSINE', 'rough', 'quadratic', 'scan_errors']

FTOL = 1e-4          # a fit ends at a step that lowers the sum of squares by less than this share of it


@dataclass
class Solution:
    x: np.ndarray         # the parameters at the end
    fun: np.ndarray       # the residual there (data rows, then linear rows)
    jac: np.ndarray       # a fresh finite-difference Jacobian there (when asked for), else the last one
    evaluations: int      # simulations of the data rows
    status: int           # of the last least_squares call
    difference: object = None   # (x, data rows, step) -> forward differences of the data rows


class _Differences:
    """Residual and Jacobian callables for least_squares: the costly rows cached by x, their
    Jacobian by forward differences, the linear rows exact."""

    def __init__(self, data, lin_rows, lin_jac, lo, hi, step):
        self.data, self.lin_rows, self.lin_jac = data, lin_rows, lin_jac
        self.lo, self.hi, self.step = lo, hi, step
        self.cache: dict = {}
        self.evaluations = 0
        self.J = None           # Jacobian of the data rows
        self.at = None          # x where J was last set

    def rows(self, x):
        key = x.tobytes()
        if key not in self.cache:
            if len(self.cache) > 8:
                self.cache.pop(next(iter(self.cache)))
            self.cache[key] = np.asarray(self.data(x), float)
            self.evaluations += 1
        return self.cache[key]

    def fun(self, x):
        return np.concatenate([self.rows(x), self.lin_rows(x)])

    def difference(self, x, r0, step=None, cols=None):
        """Forward differences, each step ``step`` (default the fit's) relative to max(1, |x|), turned back
        inside the bounds (as scipy's '2-point' scheme); of the columns ``cols`` only (default all, the
        others zero)."""
        step = self.step if step is None else step
        J = np.zeros((len(r0), len(x)))
        for i in range(len(x)) if cols is None else cols:
            h = step[i] * max(1.0, abs(x[i]))
            if not self.lo[i] <= x[i] + h <= self.hi[i]:
                h = -h
            xi = x.copy()
            xi[i] += h
            h = xi[i] - x[i]
            J[:, i] = (self.rows(xi) - r0) / h
        return J

    def jac(self, x):
        self.J, self.at = self.difference(x, self.rows(x)), x.copy()
        return np.vstack([self.J, self.lin_jac])


def solve(data, x0, lo, hi, max_nfev: int, step, lin_rows=None, lin_jac=None,
          final_jacobian: bool = True) -> Solution:
    """Minimise |data(x)|^2 + |lin_rows(x)|^2 over lo <= x <= hi.

    ``data``: the costly residual; ``lin_rows``, ``lin_jac``: rows linear in x and their
    constant Jacobian (or None); ``step``: relative finite-difference step per parameter;
    ``max_nfev``: residual evaluations least_squares may make (the differences not counted, as
    in scipy), over all restarts. With ``final_jacobian`` the returned Jacobian is a fresh
    difference at the returned x (for standard errors)."""
    n = len(x0)
    if lin_rows is None:
        lin_rows, lin_jac = (lambda x: np.zeros(0)), np.zeros((0, n))
    step = np.broadcast_to(np.asarray(step, float), (n,))
    s = _Differences(data, lin_rows, lin_jac, lo, hi, step)
    x, budget, status = np.asarray(x0, float), max_nfev, 0
    while budget > 0:
        sol = least_squares(s.fun, x, jac=s.jac, bounds=(lo, hi), max_nfev=budget, method='trf', ftol=FTOL)
        budget -= sol.nfev
        x, status = sol.x, sol.status
        if status <= 0 or np.array_equal(s.at, x):
            break        # the budget is spent, or it stopped on a fresh Jacobian
    r = s.rows(x)
    if final_jacobian and not np.array_equal(s.at, x):
        s.J, s.at = s.difference(x, r), x.copy()
    jac = np.vstack([s.J, lin_jac]) if s.J is not None else np.vstack([s.difference(x, r), lin_jac])
    return Solution(x, np.concatenate([r, lin_rows(x)]), jac, s.evaluations, status, s.difference)


ROUGH_COSINE = 0.8      # forward and backward differences less alike than this: the error is rough there
PROBE_SIGMAS = (2.0, 4.0)   # the sum of squares is probed this many standard errors each way along each parameter
QUADRATIC_RISE = 0.5    # and must rise by this share of a quadratic's rise there (2 and 8 levels)
SCAN_SIGMAS = 2.0       # a rough parameter's error: half the reach of the region where the sum of squares
SCAN_STOP = 9.0         # rises by less than SCAN_SIGMAS^2 levels; a side ends after two probes above SCAN_STOP levels
SCAN_REACH = 2.0        # or at this distance (scaled units: twice the parameter's size)


def rough(difference, x, r0, step, cols):
    """Cosine between forward and backward differences of the data rows ``r0`` at ``x`` with the
    relative ``step`` (a tenth of the fit's: small enough that a smooth but strongly nonlinear
    parameter, a ripple's period over many periods, still differences alike both ways), for the
    parameters ``cols`` (1 for the others): near 1 where the simulated error is smooth in a
    parameter; where the simulation depends on it chaotically (a drive's contact ringing through
    many knocks) the two are unrelated."""
    ahead = difference(x, r0, np.asarray(step), cols)
    back = difference(x, r0, -np.asarray(step), cols)
    num = np.sum(ahead * back, axis=0)
    den = np.linalg.norm(ahead, axis=0) * np.linalg.norm(back, axis=0)
    return np.where(den > 0, num / np.where(den > 0, den, 1.0), 1.0)


def quadratic(objective, x, lo, hi, se, level, at: float, cols):
    """The parameters of ``cols`` along which the sum of squares ``objective`` (``at`` at ``x``) does not
    rise by QUADRATIC_RISE of a quadratic's rise at each of PROBE_SIGMAS standard errors ``se`` each way,
    the others fixed (a quadratic sum of squares rises by PROBE_SIGMAS^2 levels there, more where
    parameters are correlated): there the Jacobian's error is too small (a profile with a long flat side:
    a drive's contact stiffness fitted at 77 kN/m +/- 25 kN/m by the Jacobian, whose sum of squares rose by
    4 levels, not 16, at 4 of those errors, on the side of the true 200 kN/m). ``level``: the rise one
    standard error costs, per parameter."""
    out = []
    for i in cols:
        if not (np.isfinite(se[i]) and se[i] > 0):
            continue
        for sign, bound in ((1.0, hi[i]), (-1.0, lo[i])):
            for k in PROBE_SIGMAS:
                d = min(k * se[i], abs(bound - x[i]))
                if d <= 0.0:
                    break
                xi = x.copy()
                xi[i] += sign * d
                if objective(xi) - at < QUADRATIC_RISE * (d / se[i]) ** 2 * level[i]:
                    out.append(i)
                    break
                if d < k * se[i]:           # the bound stopped this probe: none farther on this side
                    break
            if out and out[-1] == i:
                break
    return out


def scan_errors(objective, x, lo, hi, se, level, at: float, which):
    """Errors of the parameters ``which`` from the sum of squares ``objective`` along each alone (the
    Jacobian's errors ``se`` mean nothing where the error is rough: it measures how much the
    prediction changes, not whether it gets worse). Each side is probed at distances doubling from
    max(2 se, 0.01) up to SCAN_REACH or the bound. A rough sum of squares jitters between nearby
    values by more than its statistical level: the jitter (RMS of the rises at the two nearest
    probes each side about the best c d^2 through them) counts as a level too. The error is half
    the farthest probe where the sum of squares (``at`` at ``x``) rose by less than SCAN_SIGMAS^2
    levels (or SCAN_SIGMAS jitters), no less than ``se``; a side ends after two probes above
    SCAN_STOP levels (and three jitters). Returns the errors and, per parameter, '' or the bound(s)
    that a low probe reached ('lo', 'hi', 'both'). ``level``: the rise one standard error costs, per
    parameter."""
    out, reach = np.array(se, float), [''] * len(x)
    for i in which:
        sides: list = []
        for sign, bound in ((1.0, hi[i]), (-1.0, lo[i])):
            room = min(abs(bound - x[i]), SCAN_REACH)
            first = max(2.0 * (se[i] if np.isfinite(se[i]) else 0.0), 0.01)
            steps: list = []
            while room > 0.0 and (not steps or steps[-1] < room):
                steps.append(min(first * 2.0 ** len(steps), room))
            sides.append((sign, steps, abs(bound - x[i]) <= SCAN_REACH, []))

        def probe(sign, step, i=i):
            xi = x.copy()
            xi[i] += sign * step
            return (objective(xi) - at) / level[i]
        for sign, steps, _, rises in sides:
            rises += [probe(sign, d) for d in steps[:2]]
        # the jitter: what a rise growing with the squared distance does not explain at the near probes
        near = np.array([(d, r) for _, steps, _, rises in sides for d, r in zip(steps, rises)]).reshape(-1, 2)
        jitter = 0.0
        if len(near):
            d2 = near[:, 0] ** 2
            c = float(d2 @ near[:, 1] / (d2 @ d2))
            jitter = float(np.sqrt(np.mean((near[:, 1] - c * d2) ** 2)))
        want, stop = max(SCAN_SIGMAS ** 2, SCAN_SIGMAS * jitter), max(SCAN_STOP, 3.0 * jitter)
        far, hit = 0.0, []
        for sign, steps, bounded, rises in sides:
            for d in steps[len(rises):]:
                if len(rises) >= 2 and min(rises[-2:]) >= stop:
                    break
                rises.append(probe(sign, d))
            low = [d for d, r in zip(steps, rises) if r < want]
            if low:
                far = max(far, max(low))
                if bounded and max(low) >= steps[-1] and len(rises) == len(steps):
                    hit.append('hi' if sign > 0 else 'lo')
        out[i] = max(out[i] if np.isfinite(out[i]) else 0.0, far / SCAN_SIGMAS)
        reach[i] = 'both' if len(hit) == 2 else (hit[0] if hit else '')
    return out, reach
