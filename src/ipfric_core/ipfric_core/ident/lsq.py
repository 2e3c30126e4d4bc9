"""Bounded least squares of a simulation error whose Jacobian is costly.

A finite-difference Jacobian of the simulation error costs one simulation of every window
per parameter, and stick-slip makes the error only piecewise smooth, so its valleys are
crossed in many short steps. :func:`solve` drives ``scipy.optimize.least_squares``
(trust region reflective) with a Jacobian that is differenced afresh only every
``refresh`` accepted steps and updated in between by Broyden's rank-one secant
update from the step just taken (which costs nothing: both ends are simulated
anyway). A fresh difference is taken at once when the last step gained less than a
quarter of what the Jacobian promised, when steps were rejected since the last one, and
before the fit is allowed to stop: a fit that stops on an updated Jacobian is
restarted from its end with a fresh one.

Rows that are linear in the parameters (the priors) are given with their exact
Jacobian and never differenced.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

REFRESH = 5          # accepted steps between fresh finite differences
GOOD_RATIO = 0.25    # a step that gains less than this share of the promised drop refreshes the Jacobian
SLOW = 0.01          # and so does a step that lowers the sum of squares by less than this share
FRESH_FIRST = 3      # the first steps of a fit (far from its optimum) always take fresh differences
FTOL = 1e-4          # a fit ends at a step that lowers the sum of squares by less than this share of it


@dataclass
class Solution:
    x: np.ndarray         # the parameters at the end
    fun: np.ndarray       # the residual there (data rows, then linear rows)
    jac: np.ndarray       # a fresh finite-difference Jacobian there (when asked for), else the last one
    evaluations: int      # simulations of the data rows
    status: int           # of the last least_squares call
    difference: object = None   # (x, data rows, step) -> forward differences of the data rows


class _Secant:
    """Residual and Jacobian callables for least_squares (see the module docstring)."""

    def __init__(self, data, lin_rows, lin_jac, lo, hi, step, refresh):
        self.data, self.lin_rows, self.lin_jac = data, lin_rows, lin_jac
        self.lo, self.hi, self.step, self.refresh = lo, hi, step, refresh
        self.cache: dict = {}
        self.evaluations = 0
        self.J = None           # Jacobian of the data rows
        self.at = None          # (x, data rows) where J was last set
        self.age = 0            # secant updates since the last fresh difference
        self.trials: list = []  # (x, data rows) evaluated since the last Jacobian
        self.force = False
        self.jacobians = 0      # Jacobians handed out

    def rows(self, x):
        key = x.tobytes()
        if key not in self.cache:
            if len(self.cache) > 8:
                self.cache.pop(next(iter(self.cache)))
            self.cache[key] = np.asarray(self.data(x), float)
            self.evaluations += 1
        return self.cache[key]

    def fun(self, x):
        r = self.rows(x)
        self.trials.append((x.copy(), r))
        return np.concatenate([r, self.lin_rows(x)])

    def difference(self, x, r0, step=None):
        """Forward differences, each step ``step`` (default the fit's) relative to max(1, |x|), turned back
        inside the bounds (as scipy's '2-point' scheme)."""
        step = self.step if step is None else step
        J = np.empty((len(r0), len(x)))
        for i in range(len(x)):
            h = step[i] * max(1.0, abs(x[i]))
            if not self.lo[i] <= x[i] + h <= self.hi[i]:
                h = -h
            xi = x.copy()
            xi[i] += h
            h = xi[i] - x[i]
            J[:, i] = (self.rows(xi) - r0) / h
        return J

    def jac(self, x):
        r = self.rows(x)
        self.jacobians += 1
        fresh = self.force or self.J is None or self.age >= self.refresh or self.jacobians <= FRESH_FIRST
        if not fresh:
            x0, r0 = self.at
            dx = x - x0
            f0, f = np.concatenate([r0, self.lin_rows(x0)]), np.concatenate([r, self.lin_rows(x)])
            model = f0 + np.vstack([self.J, self.lin_jac]) @ dx
            promised, gained = f0 @ f0 - model @ model, f0 @ f0 - f @ f
            fresh = (not (promised > 0.0 and gained >= GOOD_RATIO * promised and gained >= SLOW * (f0 @ f0))
                     or not np.any(dx) or np.any((x - self.lo) * (self.hi - x) <= 1e-12 * (self.hi - self.lo) ** 2))
        if fresh:
            self.J, self.age = self.difference(x, r), 0
        else:
            # the rejected trials since the last Jacobian, then the step taken: secants from x0
            for xt, rt in [t for t in self.trials if not np.array_equal(t[0], x)] + [(x, r)]:
                dt = xt - x0
                if np.any(dt):
                    self.J = self.J + np.outer((rt - r0) - self.J @ dt, dt) / (dt @ dt)
            self.age += 1
        self.at, self.trials, self.force = (x.copy(), r), [], False
        return np.vstack([self.J, self.lin_jac])


def solve(data, x0, lo, hi, max_nfev: int, step, lin_rows=None, lin_jac=None, refresh: int = REFRESH,
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
    s = _Secant(data, lin_rows, lin_jac, lo, hi, step, refresh)
    x, budget, status = np.asarray(x0, float), max_nfev, 0
    while budget > 0:
        s.force, s.trials = True, []
        sol = least_squares(s.fun, x, jac=s.jac, bounds=(lo, hi), max_nfev=budget, method='trf', ftol=FTOL)
        budget -= sol.nfev
        x, status = sol.x, sol.status
        settled = s.age == 0 and np.array_equal(s.at[0], x)
        if status <= 0 or settled:
            break        # the budget is spent, or it stopped on a fresh Jacobian
    r = s.rows(x)
    if final_jacobian and not (s.age == 0 and np.array_equal(s.at[0], x)):
        s.J, s.age, s.at = s.difference(x, r), 0, (x.copy(), r)
    jac = np.vstack([s.J, lin_jac]) if s.J is not None else np.vstack([s.difference(x, r), lin_jac])
    return Solution(x, np.concatenate([r, lin_rows(x)]), jac, s.evaluations, status, s.difference)
