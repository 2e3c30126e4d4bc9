"""The fitting problem of the ladder (:mod:`ipfric_core.ident.ladder`): a record cut into windows, the
simulation error of a model on them, the fit of a model's free parameters and its statistics.

Fits are bounded least squares (``scipy.optimize.least_squares``) on parameters scaled to
their typical size, with finite-difference Jacobians (:mod:`ipfric_core.ident.lsq`; they end
when a step gains less than ``lsq.FTOL``); standard errors come from the Jacobian at the end (in the
scaled parameters), inflated for the correlation of the errors within a window (the effective
sample count is the number of windows, each block of windows with its own level: :func:`block_covariance`),
and from a scan along a parameter where the error is
rough in it or rises slower than a quadratic (:class:`Errors`, :func:`lsq.scan_errors`).
"""
from __future__ import annotations

import math

import numpy as np

from ..analysis.records import Record
from ..physics.params import ConfigError
from . import lsq, shooting
from .effects import PARAMS
from .model import Model

__all__ = ['SCREEN_NFEV', 'Problem', 'fit_model', 'block_covariance', 'Errors', 'block_p_value']

BOOTSTRAP = 2000         # resamples of the windows' drops (:func:`block_p_value`)
MAX_NFEV = 40
DIFF_STEP = 5e-3
THETA_WEIGHT = 0.2       # an angle count weighs a fifth of a cart count (errors of the pendulum's start rates grow)
PRIOR_REL = 0.5         # the declared values' prior standard deviation, relative
PRIOR_COUNTS = 0.3      # RMS error [counts] that one prior standard deviation is worth
#: the candidates' short fits use windows spread over the estimation record, up to this many samples per
#: block (a 2-minute record at 1 kHz: every seventh window); the kept explanation is refitted on all
SCREEN_SAMPLES = 10000
SCREEN_NFEV = 12         # steps of a candidate's short fit


class Problem:
    """A record cut into windows, and the simulation error of a model on it: the cart's
    readings on :func:`shooting.cart_windows`, with a pendulum also its angle on
    :func:`shooting.angle_windows` (weighted THETA_WEIGHT). The last few models' predictions
    are kept (the ladder judges one model by several figures)."""

    def __init__(self, rec: Record, blocks=None, subset: bool = False):
        self.rec, self.subset = rec, subset     # subset: some of the record's windows (:meth:`screen`)
        if blocks is None:
            blocks = [('x', shooting.cart_windows(rec), 1.0)]
            if rec.theta is not None:
                blocks.append(('theta', shooting.angle_windows(rec), THETA_WEIGHT))
        self.blocks = blocks
        n = len(self.blocks[0][1])
        if n < 3:
            raise ConfigError(f'{rec.name}: only {n} windows of valid samples; the record is too short or too '
                              f'broken by overruns (at least 3 are needed)')
        self.n_windows = sum(len(w) for _, w, _ in self.blocks)
        self.n_samples = int(sum(np.sum(w.stop - w.start) for _, w, _ in self.blocks))
        self._kept: dict = {}
        self._base: dict = {}
        self._cart: Problem | None = None

    def screen(self, samples: int = SCREEN_SAMPLES) -> Problem:
        """This problem on every k-th window of each block (k the smallest that keeps a block within
        ``samples`` samples; itself when every block is that small): screens and the candidates' fits
        run on it, the kept effect is refitted on every window."""
        blocks = []
        for key, win, wt in self.blocks:
            k = max(1, math.ceil(float(np.sum(win.stop - win.start)) / samples))
            blocks.append((key, shooting.every(win, k), wt))
        if all(len(b[1]) == len(a[1]) for a, b in zip(self.blocks, blocks)):
            return self
        return Problem(self.rec, blocks, subset=True)

    def cart(self) -> Problem:
        """This problem on the cart's windows alone (the short fits of effects that do not act on the
        angle: the cart's error is what they change; the angle's weighs THETA_WEIGHT^2 as much)."""
        if len(self.blocks) == 1:
            return self
        if self._cart is None:
            self._cart = Problem(self.rec, self.blocks[:1], self.subset)
        return self._cart

    def baseline(self, model: Model, levels, prior: Model | None) -> Model:
        """``model`` with only ``levels`` refitted here by a short fit (what a short fit of an effect must
        beat on a subset of windows, where ``model`` was fitted on all); ``model`` itself on every window."""
        if not self.subset or not levels:
            return model
        key = (model.vectors(), tuple(sorted(levels)))
        if key not in self._base:
            self._base[key] = fit_model(self, model, max_nfev=SCREEN_NFEV, only=levels, prior=prior, errors=False)[0]
        return self._base[key]

    def predictions(self, model: Model) -> list:
        vec = model.vectors()
        if vec not in self._kept:
            if len(self._kept) >= 4:
                self._kept.pop(next(iter(self._kept)))
            self._kept[vec] = [shooting.predict(vec, self.rec, win) for _, win, _ in self.blocks]
        return self._kept[vec]

    def residuals(self, model: Model) -> np.ndarray:
        return np.concatenate([wt * shooting.reading_errors(p, self.rec, key)
                               for (key, _, wt), p in zip(self.blocks, self.predictions(model))])

    def cost(self, model: Model) -> float:
        """Mean squared simulation error [counts^2]."""
        return float(np.mean(self.residuals(model) ** 2))

    def cart_cost(self, model: Model) -> float:
        """Mean squared simulation error of the cart alone [counts^2] (one pass, for screening)."""
        key, win, _ = self.blocks[0]
        vec = model.vectors()
        pred = self._kept[vec][0] if vec in self._kept else shooting.predict(vec, self.rec, win)
        return float(np.mean(shooting.reading_errors(pred, self.rec, key) ** 2))

    def summary(self, model: Model) -> dict:
        out = {}
        for (key, win, _), p in zip(self.blocks, self.predictions(model)):
            out.update(shooting.summary(p, self.rec, win, key))
        return out

    def window_sse(self, model: Model) -> np.ndarray:
        return np.concatenate([wt ** 2 * shooting.window_sse(p, self.rec, win, key)
                               for (key, win, wt), p in zip(self.blocks, self.predictions(model))])


def fit_model(pr: Problem, model: Model, max_nfev: int = MAX_NFEV, only=None, prior: Model | None = None,
              errors: bool = True, profile=None) -> tuple[Model, dict]:
    """Bounded least squares of the free parameters (or of those in ``only``); returns the
    fitted model and the standard errors of the fitted parameters (:class:`Errors`; none without
    ``errors``): the Jacobian's, checked along each parameter (of ``profile``, default all) for a
    rough or flatter than quadratic sum of squares, and then from a scan along it.

    ``prior``: the declared model; each of its free values enters as a prior (standard
    deviation PRIOR_REL of its size; one standard deviation costs as much as PRIOR_COUNTS of
    RMS error on every compared sample), so that a direction the data hardly determine
    (Coulomb level against viscous slope at the low speeds of a limit cycle) stays at the
    declared value instead of wandering to a bound. The Jacobian is differenced sparingly
    (:func:`lsq.solve`)."""
    free = [p for p in model.free if only is None or p.name in only]
    if not free:
        return model, {}
    scale = np.array([max(abs(p.value), PARAMS[p.name].typical) for p in free])
    lo = np.array([p.lo for p in free]) / scale
    hi = np.array([p.hi for p in free]) / scale
    x0 = np.clip(np.array([p.value for p in free]) / scale, lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo))
    names = [p.name for p in free]
    ref = {p.name: p.value for p in prior.params} if prior is not None else {}
    anchored = [i for i, nm in enumerate(names) if nm in ref]
    z0 = np.array([ref[names[i]] for i in anchored]) / scale[anchored] if anchored else np.zeros(0)
    sd = PRIOR_REL * np.maximum(np.abs(z0), np.array([PARAMS[names[i]].typical for i in anchored]) / scale[anchored])
    weight = PRIOR_COUNTS * math.sqrt(pr.n_samples)
    lin_jac = np.zeros((len(anchored), len(names)))
    lin_jac[np.arange(len(anchored)), anchored] = weight / sd

    def data(z):
        return pr.residuals(model.with_values(dict(zip(names, z * scale))))

    def lin(z):
        return weight * (z[anchored] - z0) / sd
    sol = lsq.solve(data, x0, lo, hi, max_nfev, DIFF_STEP, lin, lin_jac,
                    final_jacobian=errors)
    fitted = model.with_values(dict(zip(names, sol.x * scale)))
    if not errors:
        return fitted, {}
    try:
        # in the scaled parameters (each about 1): in physical units the columns span ten decades (a
        # contact stiffness of 1e5 N/m beside a play of 1e-3 m) and pinv dropped the stiffest as noise
        cov, level = block_covariance(pr, fitted, sol.jac, sol.fun, len(anchored))
    except np.linalg.LinAlgError:
        return fitted, Errors(names, np.full((len(names), len(names)), np.nan))
    se = np.sqrt(np.maximum(np.diag(cov), 0.0))
    # where the Jacobian's errors are not to be trusted: a rough error (forward and backward differences
    # unlike), or one that does not rise as a quadratic would; there a scan along the parameter decides
    cols = [i for i, nm in enumerate(names) if profile is None or nm in profile]
    r0 = sol.fun[:len(sol.fun) - len(anchored)]
    cosine = lsq.rough(sol.difference, sol.x, r0, np.full(len(names), 0.1 * DIFF_STEP), cols)
    rough = [i for i in cols if cosine[i] < lsq.ROUGH_COSINE]
    seen: dict = {}

    def objective(z):
        if z.tobytes() not in seen:
            r, q = data(z), lin(z)
            seen[z.tobytes()] = float(r @ r + q @ q)
        return seen[z.tobytes()]
    at = float(sol.fun @ sol.fun)
    flat = lsq.quadratic(objective, sol.x, lo, hi, se, level, at, [i for i in cols if i not in rough])
    wide, reach = lsq.scan_errors(objective, sol.x, lo, hi, se, level, at, sorted(rough + flat))
    widen = np.where(se > 0, wide / np.where(se > 0, se, 1.0), 1.0)
    cov = cov * np.outer(widen, widen) * np.outer(scale, scale)
    return fitted, Errors(names, cov, {nm: r for nm, r in zip(names, reach) if r}, [names[i] for i in rough],
                          [names[i] for i in flat])


def block_covariance(pr: Problem, model: Model, jac: np.ndarray, fun: np.ndarray, n_prior: int
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Covariance of the fitted parameters (scaled, as ``jac``'s columns) and each one's level: the rise
    of the sum of squares that one standard error costs along it alone.

    The errors within a window are correlated (the windows count as the independent samples): each
    block's rows (:attr:`Problem.blocks`: the cart's few long windows, the angle's many short ones) carry
    its own level, its sum of squares per window, in the sandwich B^-1 (sum_b level_b J_b' J_b) B^-1
    (B = J'J, the prior's rows with the data's level per window); one block alone gives level B^-1."""
    rows = [len(shooting.reading_errors(p, pr.rec, key)) for (key, _, _), p in zip(pr.blocks, pr.predictions(model))]
    data = len(fun) - n_prior
    bread = np.linalg.pinv(jac.T @ jac)
    meat = np.zeros_like(bread)
    o = 0
    for (_, win, _), nb in zip(pr.blocks, rows):
        r, j = fun[o:o + nb], jac[o:o + nb]
        meat += float(r @ r) / max(1, len(win)) * (j.T @ j)
        o += nb
    level_all = float(fun[:data] @ fun[:data]) / max(1, pr.n_windows)
    meat += level_all * (jac[data:].T @ jac[data:])
    cov = bread @ meat @ bread
    d = np.diag(bread)
    return cov, np.where(d > 0, np.diag(cov) / np.where(d > 0, d, 1.0), level_all)


class Errors(dict):
    """Standard errors of fitted parameters by name (a dict), with their covariance (``names``,
    ``cov``, physical units), the parameters on which the simulated error is rough (``rough``) or rises
    slower than a quadratic (``flat``: both with errors from :func:`lsq.scan_errors`, their
    correlations stay the Jacobian's) and those whose scan stayed low up to a bound (``reach``: name
    -> 'lo'/'hi'/'both'): the data do not confine them."""

    def __init__(self, names, cov, reach=None, rough=(), flat=()):
        super().__init__(zip(names, map(float, np.sqrt(np.maximum(np.diag(cov), 0.0)))))
        self.names, self.cov, self.reach = list(names), np.asarray(cov, float), dict(reach or {})
        self.rough, self.flat = list(rough), list(flat)

    def correlations(self, threshold: float = 0.0) -> list[tuple[str, str, float]]:
        """(a, b, r) of every pair whose correlation is at least ``threshold`` in size, largest first."""
        sd = np.sqrt(np.maximum(np.diag(self.cov), 0.0))
        out = []
        for i in range(len(self.names)):
            for j in range(i + 1, len(self.names)):
                if sd[i] > 0 and sd[j] > 0:
                    r = float(self.cov[i, j] / (sd[i] * sd[j]))
                    if abs(r) >= threshold:
                        out.append((self.names[i], self.names[j], r))
        return sorted(out, key=lambda t: -abs(t[2]))


def block_p_value(before: np.ndarray, after: np.ndarray) -> float:
    """p-value that the squared error did not drop: bootstrap of the windows' drops."""
    d = before - after
    if not np.any(d):
        return 1.0
    rng = np.random.default_rng(0)
    boot = d[rng.integers(0, len(d), (BOOTSTRAP, len(d)))].sum(axis=1)
    return float((np.sum(boot <= 0.0) + 1) / (BOOTSTRAP + 1))
