"""Identification as a ladder of hypotheses, judged by simulation error.

The declared model (plant constants and friction law with their values) is the
hypothesis. The ladder, on one metric (the multiple-shooting simulation error of
:mod:`ipfric_core.ident.shooting`, in encoder counts):

(a) the declared model as it is;
(b) its friction refitted (known constants frozen unless freed by name); a large change of a
    declared value is reported as evidence of a missing effect;
(c) effects of the library added one at a time, each round the one that lowers the
    validation error most among those that pass every check:

- it lowers the validation simulation error by more than ``SIM_GAIN_PERCENT``, significantly
  (block bootstrap over the validation windows, p < ``P_VALUE``), and the estimation error
  too, and no reported figure (cart, angle) gets worse by more than ``WORSE_PERCENT``;
- no fitted parameter ends on a bound;
- the data do not contradict it: a deadzone below the smallest command that moved the
  cart, a saturation that no steady speed above it refutes, a delay no longer than the
  lag at which the cart answers the command, a play of at least two encoder counts, a drive
  play that the motor side crosses at three reversals at least, in two samples or more.

Each round, every candidate first gets a short fit (its own parameters and the friction
levels, SCREEN_NFEV steps from each of its starts) on the cart's windows alone (the angle's
too for an effect on the angle), on every k-th window where the estimation record holds more
than SCREEN_SAMPLES samples per block (judged on every window: a short fit that does not carry
over is done again on all); only the candidates whose short fit lowers the estimation error
by at least FULL_SHARE of the best one's are fitted in full and judged (the others are
listed with that reason and tried again next round).

Fits are bounded least squares (``scipy.optimize.least_squares``) on parameters scaled to
their typical size, with finite-difference Jacobians (:mod:`ipfric_core.ident.lsq`; they end
when a step gains less than ``lsq.FTOL``); standard errors come from the Jacobian at the end (in the
scaled parameters), inflated for the correlation of the errors within a window (the effective
sample count is the number of windows), and from a scan along a parameter where the error is
rough in it or rises slower than a quadratic (:class:`Errors`, :func:`lsq.scan_errors`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..analysis.records import Record, smooth_rate
from ..physics.params import ConfigError
from . import lsq, shooting
from .effects import EFFECTS, PARAMS
from .equation_error import BOOTSTRAP, P_VALUE
from .model import LADDER_EFFECTS, Model

__all__ = ['Problem', 'Step', 'run_ladder']

SIM_GAIN_PERCENT = 2.0
MIN_DROP_COUNTS = 0.05   # and by at least this much RMS [counts] (rounding alone leaves 0.29 count)
WORSE_PERCENT = 5.0      # a reported figure (cart, angle) may not rise by more (their noise floors move a little)
MAX_ROUNDS = 3
MAX_NFEV = 40
DIFF_STEP = 5e-3
THETA_WEIGHT = 0.2       # an angle count weighs a fifth of a cart count (errors of the pendulum's start rates grow)
PRIOR_REL = 0.5         # the declared values' prior standard deviation, relative
PRIOR_COUNTS = 0.3      # RMS error [counts] that one prior standard deviation is worth
REFIT_NOTE = 0.3         # a refit that moves a declared value by more than 30 % is reported
STOP_S = 0.05            # a stretch this long with the encoder still is a stop [s]
SCREEN_GAIN = 0.01       # an effect whose own parameters lower the estimation cost less is not refitted
#: effects started from a grid of their error: when its best point lowers the cart's estimation cost by
#: less than SCREEN_GAIN, they are not fitted (a drive play's simulation costs tens of ordinary ones)
GRID_SCREENED = ('drive_backlash',)
#: the candidates' fits use windows spread over the estimation record, up to this many samples per
#: block (a 2-minute record at 1 kHz: every second window); the kept effect is refitted on all
SCREEN_SAMPLES = 30000
SCREEN_NFEV = 12         # steps of a candidate's short fit
FULL_SHARE = 0.5         # a candidate is fitted in full when its short fit gains this share of the best one's
REDO_GAIN = 0.1          # a short fit that gains this much on a subset of windows and nothing on all is redone on all

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
    n = len(sol.fun)
    # one standard deviation of the sum of squares: its residual variance, times the samples per window
    # (the errors within a window are correlated: the windows count as the independent samples)
    level = float(sol.fun @ sol.fun) / max(1, n - len(names)) * n / max(1, pr.n_windows)
    try:
        # in the scaled parameters (each about 1): in physical units the columns span ten decades (a
        # contact stiffness of 1e5 N/m beside a play of 1e-3 m) and pinv dropped the stiffest as noise
        cov = np.linalg.pinv(sol.jac.T @ sol.jac) * level
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


# ----------------------------------------------------------------- what the data say directly
def stops_and_starts(rec: Record) -> list[tuple[int, int]]:
    """(last still sample, first moving sample) of every breakaway after a stop of STOP_S."""
    x, t = rec.x, rec.t
    moves = np.flatnonzero(np.diff(x) != 0.0)
    out = []
    for a, b in zip(moves[:-1], moves[1:]):
        if t[b] - t[a + 1] >= STOP_S:
            out.append((int(b), int(b) + 1))
    return out


def smallest_moving_command(rec: Record) -> float | None:
    """The command that moved the cart from rest [V]: the largest |command| over the 5 ms before
    each breakaway, its 10th percentile over the breakaways. A deadzone must be below it (a
    larger one would have kept the cart still)."""
    vals = []
    for still, _ in stops_and_starts(rec):
        lo = np.searchsorted(rec.t, rec.t[still] - 0.005)
        vals.append(float(np.max(np.abs(rec.u[lo:still + 1]))))
    return float(np.quantile(vals, 0.1)) if len(vals) >= 3 else None


def steady_speeds(rec: Record, hold_s: float = 0.3) -> list[tuple[float, float]]:
    """(|command| [V], |speed| [m/s]) at the end of every stretch the command stayed constant
    for ``hold_s``: a saturation at u_max is refuted by speeds still growing above it."""
    u, t = rec.u, rec.t
    change = np.flatnonzero(np.diff(u) != 0.0)
    bounds = np.concatenate([[0], change + 1, [len(u)]])
    out = []
    for a, b in zip(bounds[:-1], bounds[1:]):
        if t[b - 1] - t[a] >= hold_s and u[a] != 0.0:
            k = np.searchsorted(t, t[b - 1] - 0.1)
            if b - 1 > k:
                out.append((abs(float(u[a])), abs(float((rec.x[b - 1] - rec.x[k]) / (t[b - 1] - t[k])))))
    return out


def response_lag(rec: Record, max_lag: float = 0.1) -> float:
    """Lag [s] at which changes of the cart's acceleration follow changes of the command best (a
    step of the force is a step of the acceleration): a transport delay longer than it (plus
    two samples) is not in the data."""
    v = smooth_rate(rec.t, rec.x, rec.valid_mask, shooting.FILTER_HZ)
    du, da = np.diff(rec.u), np.diff(np.gradient(v, rec.t))
    n = int(max_lag / rec.dt)
    cc = [float(np.dot(du[:len(du) - k], da[k:])) for k in range(n)]
    return int(np.argmax(cc)) * rec.dt


def drive_crossings(pr: Problem, model: Model) -> np.ndarray:
    """Durations [s] of the model's motor side crossing its whole play (from contact on one side
    to contact on the other: a reversal of the drive force), run along ``pr``'s record
    (:func:`shooting.drive_states`)."""
    rec, vec = pr.rec, model.vectors()
    drive = vec.truth.drive_vector()
    side = shooting.drive_states(vec.pp, drive[0], drive[1], rec.t, shooting.applied_commands(vec, rec),
                                 pr.blocks[0][1].motion)[:, 2]
    touch = np.flatnonzero(side != 0.0)
    if len(touch) < 2:
        return np.zeros(0)
    before, after = touch[:-1], touch[1:]
    across = side[before] != side[after]
    return rec.t[after[across]] - rec.t[before[across]]


def contradictions(pr: Problem, model: Model, name: str) -> list[str]:
    """Why the data refute the fitted effect ``name`` (empty when nothing does)."""
    rec = pr.rec
    own = set(EFFECTS[name].params)
    why = [f'{p.name} = {p.value:.4g} {p.unit} ends on its bound [{p.lo:g}, {p.hi:g}]'
           for p in model.params if p.free and p.name in own and p.at_bound(1e-3 * PARAMS[p.name].typical)]
    if name == 'deadzone':
        low = smallest_moving_command(rec)
        if low is not None and model['deadzone_V'] >= low:
            why.append(f'deadzone {model["deadzone_V"]:.3g} V is not below {low:.3g} V, a command that moved the cart')
    if name == 'saturation':
        share = float(np.mean(np.abs(rec.u) > model['saturation_V']))
        if share < 0.01:
            why.append(f'saturation at {model["saturation_V"]:.3g} V clips {100 * share:.2g} % of the commands '
                       f'(needs 1 %)')
        above = sorted((u, s) for u, s in steady_speeds(rec) if u > model['saturation_V'])
        if len(above) >= 2 and above[-1][1] > 1.05 * above[0][1] and above[-1][0] > 1.05 * above[0][0]:
            why.append(f'saturation at {model["saturation_V"]:.3g} V, but the steady speed still grew from '
                       f'{above[0][1]:.3g} m/s at {above[0][0]:.3g} V to {above[-1][1]:.3g} m/s '
                       f'at {above[-1][0]:.3g} V')
    if name == 'delay':
        lag = response_lag(rec)
        if model['input_delay_s'] > lag + 2 * rec.dt:
            why.append(f'delay {model["input_delay_s"] * 1e3:.3g} ms exceeds the lag at which the cart answers the '
                       f'command ({lag * 1e3:.3g} ms)')
    if name == 'cogging' and np.ptp(rec.x) < 3 * model['cogging_period_m']:
        why.append(f'cogging period {model["cogging_period_m"] * 1e3:.3g} mm: fewer than 3 periods over the travel '
                   f'({np.ptp(rec.x) * 1e3:.3g} mm)')
    if name == 'backlash' and model['backlash_m'] < 2 * rec.x_resolution:
        why.append(f'play {model["backlash_m"] * 1e3:.3g} mm is below two encoder counts (quantization)')
    if name == 'drive_backlash':
        if model['drive_backlash_m'] < 2 * rec.x_resolution:
            why.append(f'drive play {model["drive_backlash_m"] * 1e3:.3g} mm is below two encoder counts '
                       f'(quantization)')
        crossings = drive_crossings(pr, model)
        if len(crossings) < 3:
            why.append(f'the motor side crosses its play at {len(crossings)} reversals of the drive force '
                       f'(needs 3)')
        elif np.median(crossings) < 2 * rec.dt:
            why.append(f'the motor side crosses its play in {np.median(crossings) * 1e3:.3g} ms (median over '
                       f'{len(crossings)} reversals), under two samples: the data cannot show it')
    return why


#: the parameters that give an effect its size (zero = no effect)
SIZE = {'deadzone': ('deadzone_V',), 'delay': ('input_delay_s',), 'cogging': ('cogging_sin_N', 'cogging_cos_N'),
        'asymmetry': ('asymmetry', 'asymmetry_viscous_Ns_per_m'), 'offset': ('offset_N',),
        'sensor_bias': ('bias_theta_rad',), 'backlash': ('backlash_m',), 'drive_backlash': ('drive_backlash_m',)}


def unresolved(model: Model, std: dict, name: str) -> list[str]:
    """The effect's size is not told from zero: every size parameter within two standard errors."""
    stds = [std.get(k) for k in SIZE.get(name, ())]
    if not stds:
        return []
    if any(s is None or not math.isfinite(s) for s in stds):
        return ['its size has no standard error (the data do not determine it)']
    sizes = [(k, model[k], float(s or 0.0)) for k, s in zip(SIZE[name], stds)]
    if all(abs(v) <= 2 * s for _, v, s in sizes):
        return ['its size is within two standard errors of zero (' +
                ', '.join(f'{k} = {v:.3g} +/- {s:.2g}' for k, v, s in sizes) + ')']
    return []


def effect_starts(pr: Problem, model: Model, name: str, prior: Model) -> list[dict]:
    """Start values of effect ``name`` (several where the fit has several minima); a start may
    also name other parameters of ``model`` (``prior``: the declared model)."""
    rec = pr.rec
    if name == 'cogging':
        return [{'cogging_period_m': p} for p in (0.002, 0.0035, 0.006, 0.01, 0.015, 0.02)]
    if name == 'delay':
        return [{'input_delay_s': d} for d in sorted({0.003, 0.01, 0.02, round(response_lag(rec), 4) or 0.001})]
    if name == 'deadzone':
        low = smallest_moving_command(rec) or 0.5
        return [{'deadzone_V': f * low} for f in (0.2, 0.5)]
    if name == 'saturation':
        umax = float(np.max(np.abs(rec.u)))
        return [{'saturation_V': f * umax} for f in (0.5, 0.8)]
    if name == 'backlash':
        return [{'backlash_m': g} for g in (3e-4, 1e-3, 3e-3)]
    if name == 'drive_backlash':
        return drive_starts(pr, model, prior)
    if name == 'sensor_bias':
        return [{'bias_theta_rad': float(np.mean(rec.theta)) if rec.theta is not None else 0.0}]
    return [{}]


#: the grid :func:`drive_starts` evaluates: plays [m], motor-side masses [share of M], contact
#: frequencies [Hz] (the contact's stiffness k = m_r (2 pi f)^2, m_r the reduced mass), and the
#: contact's damping ratio
DRIVE_GRID = ((3e-4, 1e-3, 3e-3), (0.1, 0.25, 0.5), (50.0, 100.0, 200.0), 0.15)


def drive_starts(pr: Problem, model: Model, prior: Model, keep: int = 2) -> list[dict]:
    """Start values of a drive with play: the ``keep`` best points of :data:`DRIVE_GRID` by the
    cart's estimation error (its error has many local minima: each contact frequency rings differently),
    with the friction of the declared model ``prior`` (a refit without the play distorts it: the
    Coulomb level sinks where the cart coasts through the play)."""
    gaps, shares, freqs, zeta = DRIVE_GRID
    law = {p.name: p.value for p in prior.free}
    model = model.with_values(law)
    grid = []
    for share in shares:
        mass = share * model['M']
        reduced = mass * model['M'] / (mass + model['M'])
        for f in freqs:
            k = reduced * (2 * math.pi * f) ** 2
            grid += [{'drive_backlash_m': g, 'drive_mass_kg': mass, 'drive_stiffness_N_per_m': k,
                      'drive_damping_Ns_per_m': 2 * zeta * math.sqrt(k * reduced), **law} for g in gaps]
    costs = [pr.cart_cost(model.with_effect('drive_backlash', p).with_values(p)) for p in grid]
    return [grid[i] for i in np.argsort(costs)[:keep]]


def short_fit(pe: Problem, current: Model, name: str, prior: Model, ps: Problem | None = None
              ) -> tuple[Model, float]:
    """The best short fit of ``current`` + ``name`` over its starts: the effect's own parameters with
    the friction levels (an effect the refit absorbed into them, a deadzone into the Coulomb level,
    needs them free to show), SCREEN_NFEV steps from each start, on the cart's windows of ``ps``
    (:meth:`Problem.screen`, default ``pe``; the angle's too for an effect on the angle). Returns it
    and the share by which it lowers the estimation error of every window of ``pe`` (0 for a grid
    point that explains nothing: not fitted). Where the subset's fit does not carry over to every
    window (it lowers the error by REDO_GAIN on the subset, by less than SCREEN_GAIN on all), the
    fits are done again on ``pe``; on the subset, the gain is counted from the friction levels
    refitted there alone (:meth:`Problem.baseline`), not from ``current``."""
    ps = ps or pe
    own = set(EFFECTS[name].params)
    levels = {p.name for p in current.free} & {'Fc', 'Fs_excess'}
    screen = (own - {'cogging_period_m'}) | levels
    starts = [current.with_effect(name, s).with_values(s) for s in effect_starts(ps, current, name, prior)]
    if name in GRID_SCREENED:
        costs = [ps.cart_cost(m) for m in starts]
        if min(costs) > (1 - SCREEN_GAIN) * ps.cart_cost(current):
            return starts[int(np.argmin(costs))], 0.0   # the best of a grid explains nothing: not fitted

    def fit(pr):
        pr = pr if EFFECTS[name].needs_theta else pr.cart()
        fits = [fit_model(pr, m, max_nfev=SCREEN_NFEV, only=screen, prior=prior, errors=False)[0]
                for m in starts]
        best = fits[int(np.argmin([pr.cost(m) for m in fits]))]
        return best, 1.0 - pr.cost(best) / pr.cost(pr.baseline(current, levels, prior))
    best, gain = fit(ps)
    full = 1.0 - pe.cost(best) / pe.cost(current)
    if ps is not pe and gain >= REDO_GAIN and full < SCREEN_GAIN:
        best, _ = fit(pe)
        full = 1.0 - pe.cost(best) / pe.cost(current)
    return best, full


def full_fit(pe: Problem, current: Model, best: Model, name: str, prior: Model) -> tuple[Model, dict]:
    """The fit of the effect's own parameters with the friction law's levels and slope from the short
    fit ``best``, with standard errors."""
    own = set(EFFECTS[name].params)
    joint = own | ({p.name for p in current.free} & {'Fc', 'Fs_excess', 'eps'})
    return fit_model(pe, best, only=joint, prior=prior, profile=SIZE.get(name, ()))


def candidate(pe: Problem, current: Model, name: str, prior: Model, ps: Problem | None = None
              ) -> tuple[Model, dict]:
    """:func:`short_fit`, then :func:`full_fit` when it lowers the estimation error by SCREEN_GAIN at least
    (else the short fit, without standard errors: :func:`unresolved` refuses it)."""
    best, gain = short_fit(pe, current, name, prior, ps)
    return full_fit(pe, current, best, name, prior) if gain >= SCREEN_GAIN else (best, {})


@dataclass
class Step:
    label: str
    model: Model
    std: dict
    est: dict
    val: dict
    notes: list


def run_ladder(est: Record, val: Record, declared: Model, allowed=None, progress=None) -> dict:
    """The ladder on ``est`` (fits) and ``val`` (judgement); see the module docstring."""
    say = progress or (lambda msg: None)
    pe, pv = Problem(est), Problem(val)
    steps = [Step('declared', declared, {}, pe.summary(declared), pv.summary(declared), [])]
    say(f'declared model: validation x error {steps[0].val["x_rms_counts"]:.3g} counts')
    refit, std = fit_model(pe, declared, max_nfev=60, prior=declared)
    notes = []
    for p in refit.free:
        old = declared.param(p.name).value
        if abs(p.value - old) > REFIT_NOTE * max(abs(old), PARAMS[p.name].typical):
            notes.append(f'{p.name} refitted from {old:.4g} to {p.value:.4g} {p.unit} '
                         f'({100 * (p.value - old) / (abs(old) or 1):+.0f} %): the declared model misses something')
        if p.at_bound(1e-3 * PARAMS[p.name].typical):
            notes.append(f'{p.name} = {p.value:.4g} {p.unit} ends on its bound [{p.lo:g}, {p.hi:g}]: the data '
                         f'contradict the declared law there')
    steps.append(Step('refit', refit, std, pe.summary(refit), pv.summary(refit), notes))
    say(f'refit: validation x error {steps[-1].val["x_rms_counts"]:.3g} counts')
    current, tried = refit, []
    ps = pe.screen()
    for _ in range(MAX_ROUNDS):
        sse0_v = pv.window_sse(current)
        ranked = []
        names = [name for name in LADDER_EFFECTS if name not in current.effects
                 and (allowed is None or name in allowed) and not (EFFECTS[name].needs_theta and est.theta is None)]
        short = {name: short_fit(pe, current, name, declared, ps) for name in names}
        top = max([gain for _, gain in short.values()], default=0.0)
        for name in names:
            m, screened = short[name]
            s: dict = {}
            behind = SCREEN_GAIN <= screened < FULL_SHARE * top
            if screened >= SCREEN_GAIN and not behind:
                m, s = full_fit(pe, current, m, name, declared)
            ev0, ev1 = pv.cost(current), pv.cost(m)
            ee0, ee1 = pe.cost(current), pe.cost(m)
            gain = 100 * (1 - math.sqrt(ev1 / ev0)) if ev0 > 0 else 0.0
            pval = block_p_value(sse0_v, pv.window_sse(m))
            why = contradictions(pe, m, name)
            if behind:
                why.append(f'its short fit lowers the estimation error by {100 * screened:.2g} %, less than '
                           f'{100 * FULL_SHARE:g} % of the best one\'s {100 * top:.2g} %: not fitted in full '
                           f'this round')
            else:
                why += unresolved(m, s, name)
            drop = math.sqrt(ev0) - math.sqrt(ev1)
            if gain <= SIM_GAIN_PERCENT:
                why.append(f'validation error drops by {gain:.2f} % (needs > {SIM_GAIN_PERCENT:g} %)')
            elif drop < MIN_DROP_COUNTS:
                why.append(f'validation error drops by {drop:.3g} count (needs {MIN_DROP_COUNTS:g}: below that '
                           f'it is the encoders\' rounding)')
            elif pval >= P_VALUE:
                why.append(f'the drop is not significant (p = {pval:.2g} over {pv.n_windows} windows)')
            if ee1 >= ee0:
                why.append('the estimation error does not drop')
            before, after = pv.summary(current), pv.summary(m)
            for key in ('x_rms_counts', 'theta_rms_counts'):
                if key in before and after[key] > before[key] * (1 + WORSE_PERCENT / 100):
                    why.append(f'validation {key.split("_")[0]} error rises from {before[key]:.3g} to '
                               f'{after[key]:.3g} counts')
            tried.append({'effect': name, 'validation_gain_percent': gain, 'p_value': pval,
                          'values': {n: m[n] for n in EFFECTS[name].params}, 'refused': why, 'kept': False})
            say(f'  tried {name:<11} gain {gain:6.2f} %  p {pval:.2g}  ' + ('; '.join(why) or 'passes'))
            ranked.append((gain, name, m, s, why, len(tried) - 1))
        ok = [r for r in ranked if not r[4]]
        if not ok:
            break
        gain, name, m, s, _, i = max(ok, key=lambda r: r[0])
        tried[i]['kept'] = True
        current, s = fit_model(pe, m, max_nfev=60, prior=declared)   # every free parameter together
        steps.append(Step(f'+ {name}', current, s, pe.summary(current), pv.summary(current), []))
        say(f'kept {name}: validation x error {steps[-1].val["x_rms_counts"]:.3g} counts')
    return {'steps': steps, 'tried': tried, 'estimation': est, 'validation': val}
