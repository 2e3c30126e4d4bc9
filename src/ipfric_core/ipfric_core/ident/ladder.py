"""Identification as a ladder of hypotheses, judged by simulation error.

The declared model (plant constants and friction law with their values) is the
hypothesis. The ladder, on one metric (the multiple-shooting simulation error of
:mod:`ipfric_core.ident.shooting`, in encoder counts):

the declared model as it is; then, round by round until the validation error is within
reach of what the encoders' rounding alone leaves (:func:`verdict`) or nothing passes, every
hypothesis competes against the current model (:func:`hypotheses`): its friction refitted
(known constants frozen unless freed by name: a freed one is fitted first, whatever the
verdict), each other friction law (viscous, coulomb, exponential, dynamic with its bristle
starts), each plant correction (M, alpha: a wrong back-EMF beta is the viscous slope eps's to take,
F = alpha V - (beta + eps) x'), each library effect with the friction levels
refitted and, before any refit, on the declared friction alone. A round keeps the one that
lowers the validation error most among those that pass every check:

- it lowers the validation simulation error by more than ``SIM_GAIN_PERCENT``, significantly
  (block bootstrap over the validation windows, p < ``P_VALUE``), and the estimation error
  too, and no reported figure (cart, angle) gets worse by more than ``WORSE_PERCENT`` and
  ``WORSE_COUNTS``;
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
sample count is the number of windows, each block of windows with its own level: :func:`block_covariance`),
and from a scan along a parameter where the error is
rough in it or rises slower than a quadratic (:class:`Errors`, :func:`lsq.scan_errors`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.signal import lombscargle

from ..analysis.records import Record, smooth_rate
from ..physics.params import ConfigError
from . import lsq, shooting
from .effects import EFFECTS, PARAMS, static_level
from .model import FRICTION_FITTED, LADDER_EFFECTS, LAW_PARAMS, Model

__all__ = ['PLANT_CORRECTIONS', 'Problem', 'Step', 'run_ladder', 'verdict']

P_VALUE = 0.01           # a drop is significant below this p-value
BOOTSTRAP = 2000         # resamples of the windows' drops (:func:`block_p_value`)
SIM_GAIN_PERCENT = 2.0
MIN_DROP_COUNTS = 0.05   # and by at least this much RMS [counts] (rounding alone leaves 0.29 count)
WORSE_PERCENT = 5.0      # a reported figure (cart, angle) may not rise by more (their noise floors move a little)
WORSE_COUNTS = 0.5       # and by more than this [counts RMS]: an angle error near its floor moves by a few tenths
MAX_ROUNDS = 4
#: the friction laws the ladder weighs against each other
LAWS = ('viscous', 'coulomb', 'exponential', 'dynamic')
#: the declared plant constants the ladder may correct (an effective mass with the rotor reflected, the motor's
#: force per volt); not the back-EMF beta: it acts on the cart as the viscous slope eps does, which every law fits
PLANT_CORRECTIONS = ('M', 'alpha')
CONTRIBUTION_COUNTS = 2.0  # a kept hypothesis changes the simulated motion by this much at least [counts RMS]
#: the data are explained when the error is within this factor of what the encoders' rounding alone
#: leaves, plus this many counts
EXPLAINED_FACTOR = 1.5
EXPLAINED_SLACK = 0.3
MAX_NFEV = 40
DIFF_STEP = 5e-3
THETA_WEIGHT = 0.2       # an angle count weighs a fifth of a cart count (errors of the pendulum's start rates grow)
PRIOR_REL = 0.5         # the declared values' prior standard deviation, relative
PRIOR_COUNTS = 0.3      # RMS error [counts] that one prior standard deviation is worth
UNDO_SIGMA = 2.0         # a correction that ends this many standard errors from the declared value or closer is undone
REFIT_NOTE = 0.3         # a refit that moves a declared value by more than 30 % is reported
STOP_S = 0.05            # a stretch this long with the encoder still is a stop [s]
SCREEN_GAIN = 0.01       # an effect whose own parameters lower the estimation cost less is not refitted
#: effects started from a grid of their error: when its best point lowers the cart's estimation cost by
#: less than SCREEN_GAIN, they are not fitted (a drive play's simulation costs tens of ordinary ones)
GRID_SCREENED = ('drive_backlash',)
#: the candidates' short fits use windows spread over the estimation record, up to this many samples per
#: block (a 2-minute record at 1 kHz: every seventh window); the kept explanation is refitted on all
SCREEN_SAMPLES = 10000
SCREEN_NFEV = 12         # steps of a candidate's short fit
FULL_SHARE = 0.5         # a candidate is fitted in full when its short fit gains this share of the best one's
FULL_TOP = 3             # and is among the best FULL_TOP of its group
REDO_GAIN = 0.1          # a short fit that gains this much on a subset of windows and nothing on all is redone on all
#: and one that leaves every window this much worse than the model it starts from (its friction levels
#: wandered off on the subset)
REDO_LOSS = 0.1

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
    larger one would have kept the cart still). None with a pendulum attached: its swing moves the
    cart with no command at all."""
    if rec.theta is not None:
        return None
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
    why: list[str] = []
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


def near(value: float, ref: float, s) -> bool:
    """``value`` within UNDO_SIGMA standard errors ``s`` of ``ref`` (a correction not told from the value it
    corrects); False where ``s`` is missing or not finite."""
    return s is not None and math.isfinite(s) and abs(value - ref) <= UNDO_SIGMA * s


def uncorrected(model: Model, std: dict, before: Model, names) -> list[str]:
    """A plant correction not told from the value it corrects (``before``'s: :func:`near`), or without a
    standard error (alpha 0.1 % low, 1.5 standard errors, kept on a clean cart for 0.06 count)."""
    out = []
    for n in names:
        s = std.get(n)
        if s is None or not math.isfinite(s):
            out.append(f'{n} has no standard error (the data do not determine it)')
        elif near(model[n], before[n], s):
            out.append(f'{n} = {model[n]:.4g} +/- {s:.2g} {model.param(n).unit} is within {UNDO_SIGMA:g} standard '
                       f'errors of {before[n]:.4g}: not told from it')
    return out


def rest_offset(theta: np.ndarray) -> float:
    """The mean angle's offset [rad] from the equilibrium nearest to it (upright 0, hanging +/-pi): where a
    biased angle encoder puts a pendulum at rest (a hanging one's mean is near -pi, not a bias of -3 rad
    against the bias's bound of 1 rad)."""
    mean = float(np.mean(theta))
    return mean - math.pi * round(mean / math.pi)


def effect_starts(pr: Problem, model: Model, name: str, prior: Model) -> list[dict]:
    """Start values of effect ``name`` (several where the fit has several minima); a start may
    also name other parameters of ``model`` (``prior``: the declared model)."""
    rec = pr.rec
    if name == 'cogging':
        return [{'cogging_period_m': p} for p in (0.002, 0.0035, 0.006, 0.01, 0.015, 0.02)] + ripple_starts(rec, model)
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
        return [{'bias_theta_rad': rest_offset(rec.theta) if rec.theta is not None else 0.0}]
    if name == 'lag':
        return [{'input_lag_s': tau} for tau in (0.003, 0.01, 0.03)]
    return [{}]


#: the cogging periods [m] :func:`ripple_starts` looks for (three of them at least over the travel)
RIPPLE_RANGE = (0.0015, 0.03)
#: its periodogram's frequencies per peak width (a peak is 1 / travel wide in 1/m: a period 2.6 % off over
#: 20 periods of travel drifts by half a period; from a fixed grid's points 5 % apart a 7.74 mm cogging
#: was fitted at 8.41 mm)
RIPPLE_OVERSAMPLE = 4


def ripple_starts(rec: Record, model: Model, keep: int = 2) -> list[dict]:
    """Cogging starts from the cart's force balance (:mod:`~ipfric_core.ident.equation_error`) of
    ``model``: its residual's periodogram over the position (Lomb-Scargle, periods of RIPPLE_RANGE, at
    RIPPLE_OVERSAMPLE frequencies per peak width), the ``keep`` peaks (15 % apart at least) that explain
    most of it, each with its amplitudes from the residual regressed on sin and cos(2 pi x / P) (the
    sign that lowers the balance's residual: the residual is minus the force the model lacks). From
    amplitudes of 0 the period has no gradient, and a fit from the nearest fixed period may stay at a
    small ripple of the wrong phase. Empty where the balance cannot be formed."""
    from .equation_error import Prepared, balance, parts
    try:
        pr = Prepared(rec)
        p = {q.name: q.value for q in model.params}
        active = parts(model.law, tuple(e for e in model.effects if e != 'cogging'))
        b = balance(pr, p, active)
    except (ConfigError, KeyError, ValueError):
        return []
    r, x = b.r[b.used], b.x[b.used]
    if len(r) < 50 or not np.any(r):
        return []

    travel = float(np.ptp(x))
    lo, hi = 2 * np.pi * max(1 / RIPPLE_RANGE[1], 3 / max(travel, 1e-12)), 2 * np.pi / RIPPLE_RANGE[0]
    if lo >= hi:
        return []
    omega = np.arange(lo, hi, 2 * np.pi / (RIPPLE_OVERSAMPLE * travel))
    power = lombscargle(x, r, omega)
    peaks = [i for i in range(len(power)) if power[i] >= power[max(0, i - 1):i + 2].max()]

    def explained(period: float) -> tuple[float, float, np.ndarray]:
        basis = np.column_stack([np.sin(2 * np.pi * x / period), np.cos(2 * np.pi * x / period)])
        c, *_ = np.linalg.lstsq(basis, r, rcond=None)
        return float(np.sum((basis @ c) ** 2)), period, c
    fits = [explained(2 * np.pi / omega[i]) for i in sorted(peaks, key=lambda i: -power[i])[:4 * keep]]
    out: list[dict] = []
    for _, period, c in sorted(fits, key=lambda f: -f[0]):
        if len(out) == keep:
            break
        if any(abs(period / o['cogging_period_m'] - 1) < 0.15 for o in out):
            continue
        signed = []
        for sign in (-1.0, 1.0):
            q = {'cogging_sin_N': sign * float(c[0]), 'cogging_cos_N': sign * float(c[1]), 'cogging_period_m': period}
            res = balance(pr, {**p, **q}, active + ('cogging',)).r
            signed.append((float(res @ res), q))
        out.append(min(signed, key=lambda t: t[0])[1])
    return out


#: the lightest motor side of a drive with play the ladder fits [share of the cart's mass]
MIN_DRIVE_SHARE = 0.02
#: the grid :func:`drive_starts` evaluates: plays [m], motor-side masses [share of M], contact
#: frequencies [Hz] (the contact's stiffness k = m_r (2 pi f)^2, m_r the reduced mass), and the
#: contact's damping ratio
DRIVE_GRID = ((3e-4, 1e-3, 3e-3), (0.1, 0.25, 0.5), (50.0, 100.0, 200.0), 0.15)


def drive_starts(pr: Problem, model: Model, prior: Model, keep: int = 2, masses=None, gaps=None) -> list[dict]:
    """Start values of a drive with play: the ``keep`` best points of :data:`DRIVE_GRID` by the
    cart's estimation error (its error has many local minima: each contact frequency rings differently),
    with the friction of the declared model ``prior`` (a refit without the play distorts it: the
    Coulomb level sinks where the cart coasts through the play). ``masses``: the motor sides [kg] to try
    instead of the grid's shares of the cart's mass; ``gaps``: the plays [m] instead of the grid's."""
    grid_gaps, shares, freqs, _ = DRIVE_GRID
    gaps = gaps or grid_gaps
    law = {n: prior[n] for n in LAW_PARAMS[prior.law]}
    model = model.with_values(law)
    grid = []
    for mass in masses or [share * model['M'] for share in shares]:
        reduced = mass * model['M'] / (mass + model['M'])
        for f in freqs:
            k = reduced * (2 * math.pi * f) ** 2
            grid += [{'drive_backlash_m': g, 'drive_mass_kg': mass, 'drive_stiffness_N_per_m': k,
                      'drive_damping_Ns_per_m': contact_damping(k, mass, model['M']), **law} for g in gaps]
    costs = [pr.cart_cost(model.with_effect('drive_backlash', p).with_values(p)) for p in grid]
    return [grid[i] for i in np.argsort(costs)[:keep]]


@dataclass
class Hypothesis:
    """One explanation of what the current model misses: a model with some parameters to fit.

    kind : 'friction' (the declared law refitted), 'law' (another friction law), 'plant' (a declared
        constant corrected: the effective mass with the rotor reflected, the motor's alpha or beta) or
        'effect' (one of the library's, with the friction levels refitted beside it or, on the declared
        friction, alone)
    own : the parameters that are the hypothesis (checked: bounds, size, relevance)
    free : the parameters its short fit moves (own, and the friction levels where they may move)
    """

    label: str
    kind: str
    model: Model
    own: tuple
    free: tuple
    starts: list = field(default_factory=lambda: [{}])
    effect: str | None = None
    #: an effect of GRID_SCREENED: not fitted when the best of its starts explains nothing (False where its
    #: starts already explain what the current model does: a drive in place of a mass correction)
    screened: bool = True


def law_starts(declared: Model) -> dict:
    """Start values of every friction parameter a law switch may need: the declared model's, else the
    typical sizes."""
    return {n: declared.get(n, PARAMS[n].typical) for n in FRICTION_FITTED}


#: the Stribeck velocities a law's fit also starts from, relative to its start: from the paper's 0.105 m/s a
#: fit of a curve 0.023 m/s wide stopped at 0.15 m/s (the Coulomb level low, the viscous slope high) and
#: lost to the coulomb law, whose lack of a curve then looked like an effect
STRIBECK_FACTORS = (0.25, 4.0)


def stribeck_starts(model: Model) -> list[dict]:
    """Further starts of a law with a Stribeck curve: its Stribeck velocity times STRIBECK_FACTORS (within
    its range); none for a law without one."""
    if 'v_s' not in LAW_PARAMS[model.law]:
        return []
    p = model.param('v_s')
    return [{'v_s': min(max(f * p.value, p.lo), p.hi)} for f in STRIBECK_FACTORS]


#: presliding displacements [m] the bristle starts of the dynamic law are taken at (sigma0 = Fs / z)
BRISTLE_Z = (1e-4, 1e-5)


def peak_level(model: Model) -> float:
    """The highest level of the model's Stribeck curve [N]: the static level, or the Coulomb level where the
    curve rises with speed (Fs_excess < 0)."""
    return model['Fc'] + max(model['Fs_excess'], 0.0)


def bristle_starts(model: Model) -> list[dict]:
    """Start values of the dynamic law's bristles: a stiffness that holds the static level within each
    presliding displacement of BRISTLE_Z, damped critically on the cart's mass (sigma1 = 2 sqrt(sigma0 M))."""
    fs = peak_level(model)
    p = model.param('sigma0')
    out = []
    for z in BRISTLE_Z:
        s0 = min(max(fs / z, p.lo), 0.5 * p.hi)
        out.append({'sigma0': s0, 'sigma1': min(2 * math.sqrt(s0 * model['M']), PARAMS['sigma1'].hi)})
    return out


def balance_starts(rec: Record, model: Model) -> dict[str, dict]:
    """Start values from the cart's force balance (equation error on filtered derivatives:
    :func:`~ipfric_core.ident.equation_error.base_fit`) of the model's friction law: ``'refit'`` its
    friction with the model's mass held; ``'M'`` the mass and friction the balance fits with the mass
    free, ``'alpha'`` the same balance read with the mass as declared (paper eq. 2 divided by M / M_fit:
    alpha, the viscous term beta + eps and the friction levels over that ratio). A simulation fit from
    the declared friction can end far from these where the declared values are far off (a viscous slope
    of 3 N s/m declared where the cart has 0.2). Empty where the balance cannot be fitted (a record that
    hardly moves)."""
    from .equation_error import Prepared, base_fit
    law = LAW_PARAMS[model.law]
    if model.law not in ('exponential', 'coulomb', 'viscous'):
        return {}
    try:
        pr = Prepared(rec)
        held = base_fit(rec, model.law, model['M'], pr).params
        free = base_fit(rec, model.law, None, pr).params
    except (ConfigError, ValueError, np.linalg.LinAlgError):
        return {}
    out = {'refit': {n: held[n] for n in law}, 'M': {'M': free['M'], **{n: free[n] for n in law}}}
    k = free['M'] / model['M']
    if k > 0:
        scaled = {n: free[n] / k for n in law if n in ('Fc', 'Fs_excess')}
        if 'eps' in law:
            scaled['eps'] = max((model['beta'] + free['eps']) / k - model['beta'], 0.05 * PARAMS['eps'].typical)
        out['alpha'] = {'alpha': model['alpha'] / k, **{n: free[n] for n in law}, **scaled}
    return out


def hypotheses(pe: Problem, current: Model, declared: Model, allowed=None, balance: dict | None = None
               ) -> list[Hypothesis]:
    """The explanations a round tries against ``current`` (see :class:`Hypothesis`): the declared law
    refitted (until it is), each other law, each plant correction not made yet, each library effect not
    added (``allowed`` restricts them), with the friction levels refitted and, before any refit, also
    on the declared friction alone. ``balance``: further starts of the refit and the plant corrections
    (:func:`balance_starts`). A law refitted with some of its levels held (:func:`full_fit`) counts as
    refitted, and the held ones stay held: the data did not determine them."""
    rec = pe.rec
    law = LAW_PARAMS[current.law]
    refitted = any(current.param(n).free for n in law)
    levels = tuple(n for n in ('Fc', 'Fs_excess') if n in law and (current.param(n).free or not refitted))
    balance = balance or {}
    out = []
    if not refitted:
        out.append(Hypothesis('refit', 'friction', current.with_free(law), law, law,
                              [{}] + stribeck_starts(current) + ([balance['refit']] if 'refit' in balance else [])))
    for other in LAWS:
        if other != current.law:
            m = current.with_law(other, law_starts(declared))
            if other == 'dynamic':      # bristles stiffer than a tenth of a count of presliding are not seen
                m = m.with_bounds('sigma0', 0.0, 10 * peak_level(m) / rec.x_resolution)
            out.append(Hypothesis(f'law {other}', 'law', m, LAW_PARAMS[other], LAW_PARAMS[other],
                                  bristle_starts(m) if other == 'dynamic' else [{}] + stribeck_starts(m)))
    for name in PLANT_CORRECTIONS:
        if not current.param(name).free:
            out.append(Hypothesis(f'{name} corrected', 'plant', current.with_free((name,) + law), (name,),
                                  (name,) + law, [{}] + ([balance[name]] if name in balance else [])))
    for name in LADDER_EFFECTS:
        if name in current.effects or (allowed is not None and name not in allowed):
            continue
        if EFFECTS[name].needs_theta and rec.theta is None:
            continue
        own = EFFECTS[name].params
        starts = effect_starts(pe, current, name, declared)
        base = current.with_effect(name)
        if name == 'drive_backlash':   # a motor side lighter than this is no drive (and its contact rings at kHz)
            base = base.with_bounds('drive_mass_kg', MIN_DRIVE_SHARE * current['M'], math.inf)
        out.append(Hypothesis(name, 'effect', base.with_free(levels), own, own + levels, starts, name))
        if name == 'drive_backlash' and current.param('M').free and current['M'] > declared['M']:
            out.append(in_place_of_mass(pe, current, declared, levels))
        if not refitted:
            out.append(Hypothesis(f'{name} on the declared friction', 'effect', base, own, own, starts, name))
    return out


#: the plays [m] of a drive in place of a mass correction (a play the mass explained is a small one)
IN_PLACE_GAPS = (1e-4, 3e-4, 1e-3)


def in_place_of_mass(pe: Problem, current: Model, declared: Model, levels: tuple) -> Hypothesis:
    """A drive with play in place of a mass correction: the cart's mass as declared again, the mass the
    correction added on the drive's motor side (a rotor and gears reflected to the rack move with the
    cart while the play is closed: a heavier cart, until the drive reverses), the friction as fitted
    with the correction; its starts from :func:`drive_starts` with that motor side."""
    name = 'drive_backlash'
    base = current.holding({'M': declared['M']}).with_effect(name)
    base = base.with_bounds('drive_mass_kg', MIN_DRIVE_SHARE * declared['M'], math.inf)
    extra = current['M'] - declared['M']
    starts = drive_starts(pe, base, current, masses=[extra], gaps=IN_PLACE_GAPS)
    own = EFFECTS[name].params
    return Hypothesis(f'{name} in place of M corrected', 'effect', base.with_free(levels), own, own + levels,
                      starts, name, screened=False)


def short_fit(pe: Problem, current: Model, h: Hypothesis, prior: Model, ps: Problem) -> tuple[Model, float]:
    """The best short fit of hypothesis ``h`` over its starts (SCREEN_NFEV steps each, its ``free``
    parameters) on the cart's windows of ``ps`` (:meth:`Problem.screen`; the angle's too for an effect on
    the angle), and the share by which it lowers the estimation error of every window of ``pe`` (0 for a
    drive play whose best grid point explains nothing: not fitted). Where the subset's fit does not
    carry over to every window (it gains REDO_GAIN on the subset, less than SCREEN_GAIN on all, or it
    leaves all REDO_LOSS worse than ``current``: its friction levels wandered off on the subset), the
    fits are done again on ``pe``; on the subset, the gain is counted from the friction levels refitted
    there alone (:meth:`Problem.baseline`), not from ``current``."""
    starts = [h.model.with_values(s) for s in h.starts]
    if h.effect in GRID_SCREENED and h.screened:
        costs = [ps.cart_cost(m) for m in starts]
        if min(costs) > (1 - SCREEN_GAIN) * ps.cart_cost(current):
            return starts[int(np.argmin(costs))], 0.0   # the best of a grid explains nothing: not fitted
    levels = set(h.free) - set(h.own)
    on_angle = h.effect is not None and EFFECTS[h.effect].needs_theta

    def fit(pr):
        pr = pr if on_angle else pr.cart()
        fits = [fit_model(pr, m, max_nfev=SCREEN_NFEV, only=set(h.free), prior=prior, errors=False)[0]
                for m in starts]
        best = fits[int(np.argmin([pr.cost(m) for m in fits]))]
        return best, 1.0 - pr.cost(best) / pr.cost(pr.baseline(current, levels, prior))
    best, gain = fit(ps)
    full = 1.0 - pe.cost(best) / pe.cost(current)
    if ps is not pe and full < SCREEN_GAIN and (gain >= REDO_GAIN or full < -REDO_LOSS):
        best, _ = fit(pe)
        full = 1.0 - pe.cost(best) / pe.cost(current)
    return best, full


def short_fits(pe: Problem, current: Model, hs: list[Hypothesis], prior: Model, ps: Problem
               ) -> list[tuple[Model, float]]:
    """:func:`short_fit` of every hypothesis of a round, the refit's first: each effect that refits the
    friction levels beside its own parameters then starts from the whole law as the refit's short fit
    left it, and fits the law with its own parameters in full. From the declared friction, a short fit of
    the levels alone could not reach what the refit reaches by the viscous slope and the Stribeck
    velocity too, and every such effect lost to the refit, or to a plant correction that took the refit
    with it (a delay of a sixth of a sample answered by alpha 0.8 % low). A plant correction, which
    refits the whole law itself, starts from both: a refit without it may have bent the friction to
    make up for a wrong mass (a motor side that moves with the cart: the viscous slope sank to 0)."""
    out: dict[int, tuple[Model, float]] = {i: short_fit(pe, current, h, prior, ps)
                                           for i, h in enumerate(hs) if h.kind == 'friction'}
    seed = {}
    if out:
        refit = next(iter(out.values()))[0]
        law = LAW_PARAMS[refit.law]
        seed = {n: refit[n] for n in law}
    for i, h in enumerate(hs):
        if i in out:
            continue
        if seed and h.kind == 'effect' and set(h.free) - set(h.own):
            h = replace(h, model=h.model.with_free(law), starts=[{**seed, **st} for st in h.starts])
        elif seed and h.kind == 'plant':
            h = replace(h, starts=h.starts + [seed])
        hs[i] = h
        out[i] = short_fit(pe, current, h, prior, ps)
    return [out[i] for i in range(len(hs))]


def joint(h: Hypothesis, model: Model) -> set:
    """The parameters a hypothesis's full fit moves: its own and those the model already fits (its
    friction law's among them)."""
    return set(h.free) | {p.name for p in model.free}


def full_fit(pe: Problem, h: Hypothesis, best: Model, prior: Model) -> tuple[Model, dict]:
    """The fit of the hypothesis's parameters with every parameter the model already fits (:func:`joint`),
    from its short fit ``best``. A refit of the declared law that puts one of its levels on a bound is done
    again with that level held at its declared value, and any hypothesis that fits the Coulomb level and
    ends with it within two standard errors of zero (:func:`untold`) with it held at its value in the
    hypothesis's start model (the declared one, or the one an earlier round fitted): the data did not
    determine it (below the Stribeck velocity the Coulomb level and the curve's width trade; a balancing
    loop's cart seldom stops), and neither a bound nor a cart without Coulomb friction is an answer (an
    amplifier clipping at 2.7 V that explained a balancing loop to its floor was refused for an Fc of
    0.07 +/- 0.13 N). Returns the model and its standard errors where that test computed them at it (else
    {}: :func:`confirm` computes them)."""
    m = fit_model(pe, best, only=joint(h, best), prior=prior, errors=False)[0]
    contact = contact_held(m)
    if contact:
        m = fit_model(pe, m.holding(contact), only=joint(h, best) - set(contact), prior=prior, errors=False)[0]
    fits_fc = 'Fc' in {p.name for p in m.free}
    if h.kind != 'friction' and not fits_fc:
        return m, {}
    held: dict = dict(contact)
    std: dict = {}
    for _ in LAW_PARAMS[m.law]:      # a level held, another may go to its bound: until none does
        new = {p.name: prior[p.name] for p in bound_params(m)
               if h.kind == 'friction' and p.name in LAW_PARAMS[m.law]}
        if not new and fits_fc and 'Fc' not in held:
            std = errors_of(pe, h, m, prior)
            if untold(m, std):
                new = {'Fc': h.model['Fc']}
        if not new:
            break
        held.update(new)
        std = {}
        m = fit_model(pe, m.holding(held), only=joint(h, best) - set(held), prior=prior, errors=False)[0]
    return m, std


def contact_held(model: Model) -> dict:
    """The damping of a drive's contact where a fit put it on a bound, at the damping ratio of
    :data:`DRIVE_GRID` for the fitted stiffness and masses: a stiff contact rings for a few milliseconds
    at each knock, too briefly for the encoder to tell its damping (the play, the motor side and the
    friction, which the data do fix, are fitted again with it held there)."""
    p = model.param('drive_damping_Ns_per_m') if 'drive_backlash' in model.effects else None
    if p is None or not p.free or p not in bound_params(model):
        return {}
    return {p.name: contact_damping(model['drive_stiffness_N_per_m'], model['drive_mass_kg'], model['M'])}


def contact_damping(stiffness: float, motor: float, cart: float) -> float:
    """The damping [N s/m] of a drive's contact of ``stiffness`` [N/m] between a motor side and a cart of
    those masses [kg] at the damping ratio of :data:`DRIVE_GRID` (on their reduced mass)."""
    reduced = motor * cart / (motor + cart)
    return 2 * DRIVE_GRID[3] * math.sqrt(stiffness * reduced)


def errors_of(pe: Problem, h: Hypothesis, model: Model, prior: Model) -> dict:
    """The standard errors of a fitted hypothesis's parameters at its fit (no step taken: the Jacobian
    there, checked along each parameter of its own; :func:`fit_model`)."""
    return fit_model(pe, model, max_nfev=0, only=joint(h, model), prior=prior,
                     profile=set(SIZE.get(h.effect or '', ())) | set(h.own))[1]


#: parameters whose lower bound is the simpler law itself, not a limit of physics: in the coulomb law,
#: static friction no higher than the Coulomb level is Coulomb friction without stiction (the data saw no
#: sticking); the laws with a Stribeck curve take a static level below it (a friction that rises with speed)
NESTED_AT_LOWER = ('Fs_excess',)


def no_static_level(model: Model, p) -> bool:
    """True when ``p`` is Fs_excess and puts the static level Fc + Fs_excess at 0 or below (no static
    friction at all: :func:`~ipfric_core.ident.effects.static_level`)."""
    return p.name == 'Fs_excess' and static_level(model['Fc'], p.value) <= 1e-3 * PARAMS[p.name].typical


def bound_params(model: Model) -> list:
    """The fitted parameters of ``model`` that end on a bound of their range; but for
    :data:`NESTED_AT_LOWER` at their lower one; Fs_excess also where :func:`no_static_level`."""
    def refutes(p) -> bool:
        tol = 1e-3 * PARAMS[p.name].typical
        if no_static_level(model, p):
            return True
        return p.at_bound(tol) and not (p.name in NESTED_AT_LOWER and p.value - p.lo <= tol)
    return [p for p in model.free if refutes(p)]


def on_bounds(model: Model) -> list[str]:
    """Why a fitted parameter of ``model`` refutes it: it ends on a bound of its range (a bound reached
    means the law or the effect is refuted there; :func:`bound_params`)."""
    def bound(p) -> str:
        if no_static_level(model, p):
            return f'-Fc = {-model["Fc"]:.4g} N: no static friction'
        return f'[{p.lo:g}, {p.hi:g}]'
    return [f'{p.name} = {p.value:.4g} {p.unit} ends on its bound {bound(p)}' for p in bound_params(model)]


def untold(model: Model, std: dict) -> list[str]:
    """A friction level that is not told from zero refutes the model: a real cart slides against a
    Coulomb level (Fc within two standard errors of 0 means the model makes up for something else)."""
    s = std.get('Fc')
    if 'Fc' in {p.name for p in model.free} and s is not None and math.isfinite(s) and model['Fc'] <= 2 * s:
        return [f'Fc = {model["Fc"]:.3g} +/- {s:.2g} N is not told from zero: a real cart slides against a '
                f'Coulomb level; the model makes up for something else']
    return []


def contribution(parts: tuple[Problem, ...], model: Model, without: Model) -> float:
    """RMS difference [counts] of the cart's predicted readings of ``model`` and ``without`` over the cart's
    windows of every part of the record (estimation and validation): what the hypothesis does to the
    simulated motion. The validation part alone judges whether it generalises (:func:`drop_checks`); its
    size is the record's (a 0.005 N cogging of 7.7 mm changed a cart's estimation part by 4 counts and its
    validation part by 1.1, and was refused as too small to matter)."""
    sq, n = 0.0, 0
    for pr in parts:
        _, win, _ = pr.blocks[0]
        a, b = pr.predictions(model)[0], shooting.predict(without.vectors(), pr.rec, win)
        c = a.compared & np.isfinite(a.x) & np.isfinite(b.x)
        d = (a.x[c] - b.x[c]) / pr.rec.x_resolution
        sq += float(d @ d)
        n += len(d)
    return math.sqrt(sq / n) if n else 0.0


@dataclass
class Judged:
    """A hypothesis fitted and judged on the validation data."""

    h: Hypothesis
    model: Model
    std: dict
    gain: float            # validation error drop [%]
    p_value: float
    score: float           # validation cost with the per-parameter penalty (lower is better)
    refused: list


def judge(pe: Problem, pv: Problem, current: Model, h: Hypothesis, m: Model, note: str | None, sse0_v,
          std: dict) -> Judged:
    """The checks of a fitted hypothesis that need no standard errors (module docstring); its score is
    the validation mean squared error times exp(2 k / n), k its fitted parameters and n the validation
    windows (the per-parameter penalty of an information criterion with the windows as the independent
    samples). ``note``: why it was not fitted in full (then it is refused); ``std``: its standard errors where
    :func:`full_fit` computed them (else {})."""
    ev1 = pv.cost(m)
    ee0, ee1 = pe.cost(current), pe.cost(m)
    gain, pval, dropped = drop_checks(pv, current, m, sse0_v)
    why = ([note] if note else []) + on_bounds(m)
    if h.effect and not (note or '').startswith('its short fit: '):
        why += contradictions(pe, m, h.effect)
    why += dropped
    if ee1 >= ee0:
        why.append('the estimation error does not drop')
    before, after = pv.summary(current), pv.summary(m)
    for key in ('x_rms_counts', 'theta_rms_counts'):
        if key in before and after[key] > max(before[key] * (1 + WORSE_PERCENT / 100), before[key] + WORSE_COUNTS):
            why.append(f'validation {key.split("_")[0]} error rises from {before[key]:.3g} to {after[key]:.3g} counts')
    k = len(m.free)
    return Judged(h, m, std, gain, pval, ev1 * math.exp(2 * k / max(pv.n_windows, 1)), why)


def drop_checks(pv: Problem, before: Model, m: Model, sse0_v) -> tuple[float, float, list[str]]:
    """The validation error's drop from ``before`` to ``m``: its gain [%], its p-value (``sse0_v``: the
    windows' squared errors of ``before``) and why it does not count (module docstring: more than
    SIM_GAIN_PERCENT, at least MIN_DROP_COUNTS, p < P_VALUE)."""
    ev0, ev1 = pv.cost(before), pv.cost(m)
    gain = 100 * (1 - math.sqrt(ev1 / ev0)) if ev0 > 0 else 0.0
    pval = block_p_value(sse0_v, pv.window_sse(m))
    drop = math.sqrt(ev0) - math.sqrt(ev1)
    if gain <= SIM_GAIN_PERCENT:
        return gain, pval, [f'validation error drops by {gain:.2f} % (needs > {SIM_GAIN_PERCENT:g} %)']
    if drop < MIN_DROP_COUNTS:
        return gain, pval, [f'validation error drops by {drop:.3g} count (needs {MIN_DROP_COUNTS:g}: below that '
                            f'it is the encoders\' rounding)']
    if pval >= P_VALUE:
        return gain, pval, [f'the drop is not significant (p = {pval:.2g} over {pv.n_windows} windows)']
    return gain, pval, []


def beyond_refit(pv: Problem, current: Model, judged: list[Judged]) -> None:
    """In a round where the law is not fitted yet, an effect or a plant correction fitted with the whole
    law (:func:`short_fits`) carries the refit's gain with it: it must also lower the validation error
    beyond the round's refit alone by the rule of :func:`drop_checks`, else the reasons are added to its
    ``refused`` (a sensor bias kept in a balancing loop for 6 % over the refit, where a spring from
    outside the library pulled the cart)."""
    refit = next((j for j in judged if j.h.kind == 'friction'), None)
    if refit is None:
        return
    law = LAW_PARAMS[current.law]
    sse = pv.window_sse(refit.model)
    for j in judged:
        if j is refit or j.refused or j.h.kind not in ('effect', 'plant') or not j.model.fitted(law):
            continue
        j.refused += [f'beyond the refit: {why}' for why in drop_checks(pv, refit.model, j.model, sse)[2]]


def leaner_first(passing: list[Judged], pv: Problem) -> list[Judged]:
    """``passing`` (best score first) with a leaner explanation moved ahead of the best one when the best
    one's extra parameters lower the validation error by less than SIM_GAIN_PERCENT (the dynamic law's
    bristles for 1 % over the refit: each added parameter must earn the gain an effect must), or when the
    leaner one explains the data to its encoders' floor (:func:`verdict`) with an error within the
    verdict's tolerance (EXPLAINED_FACTOR, EXPLAINED_SLACK) of the best one's: the data cannot tell them
    apart (a clean balancing loop, refitted to 27.6 counts where its rounding leaves 28, took a 3 ms lag
    for 22.1 counts; a drive's stiff bristle law at 76 counts, within its own floor, is no match for a
    mass correction at 2)."""
    if len(passing) < 2:
        return passing
    best = passing[0]
    err = pv.summary(best.model)['x_rms_counts']

    def as_good(j: Judged) -> bool:
        e = pv.summary(j.model)['x_rms_counts']
        return e * (1 - SIM_GAIN_PERCENT / 100) <= err or (
            e <= EXPLAINED_FACTOR * err + EXPLAINED_SLACK and verdict(pv, j.model)['explained'])
    lean = [j for j in passing[1:] if len(j.model.free) < len(best.model.free) and as_good(j)]
    if not lean:
        return passing
    first = min(lean, key=lambda j: (len(j.model.free), j.score))
    return [first] + [j for j in passing if j is not first]


def confirm(pe: Problem, pv: Problem, current: Model, j: Judged, prior: Model) -> None:
    """The checks of a hypothesis that passed :func:`judge` which need its standard errors (its size told
    from zero, a plant correction told from the value it corrects, a Coulomb level told from zero) and its
    contribution to the simulated motion; the reasons it fails them are added to ``j.refused``."""
    j.std = j.std or errors_of(pe, j.h, j.model, prior)
    why = untold(j.model, j.std) + (unresolved(j.model, j.std, j.h.effect) if j.h.effect else [])
    if j.h.kind == 'plant':
        why += uncorrected(j.model, j.std, current, j.h.own)
    if not why:
        size = contribution((pe, pv), j.model, undone(j, current))
        if size < CONTRIBUTION_COUNTS:
            why.append(f'it changes the simulated motion by {size:.2g} counts RMS (needs {CONTRIBUTION_COUNTS:g}: '
                       f'too small to matter at the encoders)')
    j.refused += why


def undone(j: Judged, current: Model) -> Model:
    """``j``'s model without what its hypothesis adds: the effect removed, a plant correction's constant
    back at its value in ``current`` with the friction as fitted beside it (a mass corrected by 0.1 % that
    rode in on the refit's friction is no correction), a law or a refit ``current`` itself."""
    if j.h.effect:
        return j.model.without(j.h.effect)
    if j.h.kind == 'plant':
        return j.model.with_values({n: current[n] for n in j.h.own})
    return current


def screen(hs: list[Hypothesis], short: list[tuple[Model, float]], pe: Problem, current: Model
           ) -> list[str | None]:
    """Which hypotheses are fitted in full this round: per hypothesis None, or why not. An effect with the
    friction levels free is measured by what it adds to the refit's short fit (the refit's gain it takes
    for free); the others by their gain over ``current``. A short fit the data already contradict
    (:func:`contradictions`) is refused here and takes no place in its group. A hypothesis is fitted in
    full when its gain reaches SCREEN_GAIN and FULL_SHARE of the best of its group's, and it is among the
    FULL_TOP best of it. Fitted in full whenever they reach SCREEN_GAIN, outside the ranks: the refit of the
    declared law (the hypotheses that carry it must beat it: :func:`beyond_refit`; screened out by rank, it
    left a balancing loop with nothing kept where it alone explained 37 % of the validation error), and the
    leaner laws where the refit's short fit ends on a bound (the declared law is refuted there, and a law
    with more parts ends on the same bound: a cart logged at 30 ms whose refit lost its Coulomb level kept
    nothing, the viscous law ranked fourth)."""
    refit = next((m for h, (m, _) in zip(hs, short) if h.kind == 'friction'), None)
    base = pe.cost(refit) if refit is not None else None
    refuted_law = refit is not None and any(p.name in LAW_PARAMS[refit.law] for p in bound_params(refit))
    gains = []
    refuted = []
    forced = []
    for h, (m, g) in zip(hs, short):
        levels = bool(set(h.free) - set(h.own)) and h.kind == 'effect'
        gains.append((levels, 1.0 - pe.cost(m) / base if levels and base else g))
        why = contradictions(pe, m, h.effect) if h.effect and g >= SCREEN_GAIN else []
        refuted.append('its short fit: ' + '; '.join(why) if why else None)
        leaner = h.kind == 'law' and len(h.own) < len(LAW_PARAMS[current.law])
        forced.append(g >= SCREEN_GAIN and (h.kind == 'friction' or (leaner and refuted_law)))
    alive = [(lv, g) for (lv, g), r, f in zip(gains, refuted, forced) if r is None and not f]
    top = {grp: max([g for lv, g in alive if lv == grp], default=0.0) for grp in (True, False)}
    rank = {grp: sorted((g for lv, g in alive if lv == grp), reverse=True) for grp in (True, False)}
    out: list[str | None] = []
    for (lv, g), r, f in zip(gains, refuted, forced):
        what = 'beyond the refit\'s' if lv else 'over the model\'s'
        if r is not None:
            out.append(r)
        elif f:
            out.append(None)
        elif g < SCREEN_GAIN:
            out.append(f'its short fit lowers the estimation error by {100 * g:.2g} % {what} only')
        elif g < FULL_SHARE * top[lv]:
            out.append(f'its short fit lowers the estimation error by {100 * g:.2g} % {what}, less than '
                       f'{100 * FULL_SHARE:g} % of the best one\'s {100 * top[lv]:.2g} %: not fitted in full '
                       f'this round')
        elif rank[lv].index(g) >= FULL_TOP:
            out.append(f'its short fit lowers the estimation error by {100 * g:.2g} % {what}: not among the '
                       f'{FULL_TOP} best of its group, not fitted in full this round')
        else:
            out.append(None)
    return out


@dataclass
class Step:
    label: str
    model: Model
    std: dict
    est: dict
    val: dict
    notes: list


def correction_notes(declared: Model, model: Model, std: dict, cart_alone: bool) -> list[str]:
    """A corrected plant constant, as the data say it: 'the declared M is 0.38 kg, the data say 0.52 +/-
    0.01 kg'. On the cart alone (``cart_alone``), where the data fix M / alpha only (paper eq. 2 without
    the pendulum, divided by alpha: (M / alpha) x'' = V - ((beta + eps) / alpha) x' - F / alpha), also the
    other reading of the same ratio: the other constant as declared, the friction scaled with it."""
    out = []
    for name in PLANT_CORRECTIONS:
        p = model.param(name)
        if p.free:
            s = std.get(name)
            err = f' +/- {s:.2g}' if s is not None and math.isfinite(s) else ''
            out.append(f'the declared {name} is {declared[name]:.4g} {p.unit}, the data say {p.value:.4g}{err} '
                       f'{p.unit}')
    fixed = [n for n in ('M', 'alpha') if not model.param(n).free]
    if cart_alone and len(fixed) == 1:
        other, held = fixed[0], 'alpha' if fixed[0] == 'M' else 'M'
        ratio = (model['M'] / model['alpha']) / (declared['M'] / declared['alpha'])
        value = declared[other] * (ratio if other == 'M' else 1.0 / ratio)
        out.append(f'on the cart alone the data fix M / alpha only ({model["M"] / model["alpha"]:.4g} kg V/N, '
                   f'declared {declared["M"] / declared["alpha"]:.4g}): the same motion is {other} = {value:.4g} '
                   f'{model.param(other).unit} with {held} as declared, the friction and the viscous term (beta + '
                   f'eps) times {value / declared[other]:.4g}')
    return out


def verdict(pv: Problem, model: Model) -> dict:
    """Whether the final model explains the validation data: its simulation error against what the
    encoders' rounding alone would leave (:func:`shooting.quantization_floor`), on the cart and (with a
    pendulum) the angle. Explained when each is within EXPLAINED_FACTOR of its floor plus
    EXPLAINED_SLACK counts."""
    summ = pv.summary(model)
    out: dict = {}
    ok = True
    for key, win, _ in pv.blocks:
        fl = shooting.quantization_floor(model.vectors(), pv.rec, win, key)
        out[key] = {'counts': summ[f'{key}_rms_counts'], 'percent': summ[f'{key}_percent'],
                    'floor_counts': fl[f'{key}_floor_counts'], 'floor_percent': fl[f'{key}_floor_percent']}
        ok &= out[key]['counts'] <= EXPLAINED_FACTOR * out[key]['floor_counts'] + EXPLAINED_SLACK
    x = out['x']
    if ok:
        reason = (f'explained: {x["percent"]:.3g} % of the motion is left, what the encoders\' rounding alone leaves '
                  f'({x["floor_percent"]:.3g} %)')
    else:
        worst = max(out, key=lambda k: out[k]['counts'] / max(out[k]['floor_counts'], 1e-9))
        w = out[worst]
        reason = (f'not explained: {x["percent"]:.3g} % of the motion is left ({x["counts"]:.3g} counts RMS), where '
                  f'the encoders\' rounding alone would leave {x["floor_percent"]:.3g} % ({x["floor_counts"]:.3g} '
                  f'counts)' + ('' if worst == 'x' else f'; the angle: {w["percent"]:.3g} % left, '
                                                        f'{w["floor_percent"]:.3g} % from rounding'))
    return {'explained': bool(ok), 'unexplained_percent': x['percent'], 'floor_percent': x['floor_percent'],
            'unexplained_counts': x['counts'], 'floor_counts': x['floor_counts'], 'reason': reason,
            'blocks': out}


def run_ladder(est: Record, val: Record, declared: Model, allowed=None, progress=None) -> dict:
    """The ladder on ``est`` (fits) and ``val`` (judgement): the declared model, then round by round the
    explanation that wins on validation among the competing hypotheses (:func:`hypotheses`), until the
    data are explained down to the encoders' floor or nothing passes; see the module docstring."""
    say = progress or (lambda msg: None)
    pe, pv = Problem(est), Problem(val)
    current = declared
    steps = [Step('declared', declared, {}, pe.summary(declared), pv.summary(declared), [])]
    say(f'declared model: validation x error {steps[0].val["x_rms_counts"]:.3g} counts')
    if declared.free:        # constants the user asked to fit (--free): fitted with the law first, whatever the verdict
        law = LAW_PARAMS[declared.law]
        current, s = fit_model(pe, declared.with_free(law), prior=declared)
        steps.append(Step('refit', current, s, pe.summary(current), pv.summary(current),
                          correction_notes(declared, current, s, est.theta is None) + refit_notes(declared, current)))
        say(f'refit with {", ".join(p.name for p in declared.free)}: validation x error '
            f'{steps[-1].val["x_rms_counts"]:.3g} counts')
    tried: list[dict] = []
    rounds: list[dict] = []
    ps = pe.screen()
    balance = balance_starts(est, declared) if not declared.free else {}
    for round_no in range(1, MAX_ROUNDS + 1):
        if verdict(pv, current)['explained']:
            break
        sse0_v = pv.window_sse(current)
        hs = hypotheses(pe, current, declared, allowed, balance)
        short = short_fits(pe, current, hs, declared, ps)
        notes = screen(hs, short, pe, current)
        judged = []
        for h, (m, _), note in zip(hs, short, notes):
            m, std = full_fit(pe, h, m, declared) if note is None else (m, {})
            judged.append(judge(pe, pv, current, h, m, note, sse0_v, std))
        beyond_refit(pv, current, judged)
        passing = leaner_first(sorted((j for j in judged if not j.refused), key=lambda j: j.score), pv)
        ok = []
        for j in passing:            # the standard errors of the best ones, until two pass
            confirm(pe, pv, current, j, declared)
            if not j.refused:
                ok.append(j)
                if len(ok) == 2:
                    break
        for j in judged:
            tried.append({'round': round_no, 'hypothesis': j.h.label, 'kind': j.h.kind,
                          'effect': j.h.effect or j.h.label, 'validation_gain_percent': j.gain,
                          'p_value': j.p_value, 'validation_x_rms_counts': pv.summary(j.model)['x_rms_counts'],
                          'values': {n: j.model[n] for n in j.h.own}, 'refused': j.refused,
                          'kept': bool(ok) and j is ok[0]})
            say(f'  tried {j.h.label:<30} gain {j.gain:6.2f} %  p {j.p_value:.2g}  '
                + ('; '.join(j.refused) or ('kept' if ok and j is ok[0] else 'passes')))
        others = sorted((j for j in judged if not ok or j is not ok[0]),
                        key=lambda j: (bool(j.refused), j.score if not j.refused else -j.gain))
        runner = others[0] if others else None
        if not ok:
            rounds.append({'round': round_no, 'kept': None,
                           'runner_up': _alternative(runner, pv) if runner else None})
            break
        win = ok[0]
        current, s = fit_model(pe, win.model, max_nfev=60, prior=declared)   # every fitted parameter together
        if on_bounds(current) or untold(current, s) or pv.cost(current) > pv.cost(win.model):
            current, s = win.model, win.std
        label = {'friction': 'refit', 'law': win.h.label, 'plant': win.h.label}.get(win.h.kind, f'+ {win.h.effect}')
        step_notes = correction_notes(declared, current, s, est.theta is None) if win.h.kind == 'plant' else []
        step_notes += refit_notes(declared, current) if win.h.kind in ('friction', 'law', 'plant') else []
        step_notes += held_notes(win.h, current)
        if win.h.kind == 'law' and 'Fc' not in LAW_PARAMS[current.law]:
            step_notes.append('the viscous law has no Coulomb level: a real cart slides against one, and these data '
                              'do not show it; not a final model of a real cart (the verdict says what is left)')
        step_notes += [f'{p.name} held at {p.value:.4g} {p.unit} (damping ratio {DRIVE_GRID[3]:g}): the fit put it '
                       'on a bound, the data do not determine it' for p in current.params
                       if p.name == 'drive_damping_Ns_per_m' and not p.free]
        steps.append(Step(label, current, s, pe.summary(current), pv.summary(current), step_notes))
        rounds.append({'round': round_no, 'kept': win.h.label,
                       'runner_up': _alternative(runner, pv) if runner else None})
        say(f'kept {win.h.label}: validation x error {steps[-1].val["x_rms_counts"]:.3g} counts'
            + (f'; runner-up {runner.h.label} ({pv.summary(runner.model)["x_rms_counts"]:.3g} counts)'
               if runner else ''))
    current = undo_corrections(pe, pv, declared, current, steps, say)
    v = verdict(pv, current)
    if not v['explained']:
        last = rounds[-1]['round'] if rounds else 0
        left = sorted((t for t in tried if t['round'] == last), key=lambda t: -t['validation_gain_percent'])
        v['tried'] = sorted({t['hypothesis'] for t in tried})
        v['largest_left'] = [{'hypothesis': t['hypothesis'], 'validation_gain_percent': t['validation_gain_percent'],
                              'refused': t['refused']} for t in left[:3]]
    say(v['reason'])
    return {'steps': steps, 'tried': tried, 'rounds': rounds, 'verdict': v, 'estimation': est, 'validation': val}


def undo_corrections(pe: Problem, pv: Problem, declared: Model, current: Model, steps: list, say) -> Model:
    """The final model with each plant correction that the data no longer support held at its declared
    value again: one that a later round's effect took over (a delay read first as a weaker motor) ends
    within UNDO_SIGMA standard errors of the declared value; held there and the rest refitted, it is
    undone when the validation error stays within WORSE_PERCENT (a step '<name> as declared')."""
    std = steps[-1].std
    for name in PLANT_CORRECTIONS:
        p = current.param(name)
        s = std.get(name) if isinstance(std, dict) else None
        if not p.free or declared.param(name).free or not near(p.value, declared[name], s):
            continue
        m, s2 = fit_model(pe, current.holding({name: declared[name]}), prior=declared)
        before, after = pv.summary(current)['x_rms_counts'], pv.summary(m)['x_rms_counts']
        if after > before * (1 + WORSE_PERCENT / 100) or on_bounds(m):
            continue
        note = (f'the data no longer move {name} from its declared {declared[name]:.4g} {p.unit} (the correction '
                f'ended at {p.value:.4g} +/- {s:.2g} {p.unit}): held there again')
        steps.append(Step(f'{name} as declared', m, s2, pe.summary(m), pv.summary(m), [note]))
        say(f'{name} as declared: validation x error {after:.3g} counts (with the correction {before:.3g})')
        current = m
    return current


def held_notes(h: Hypothesis, model: Model) -> list[str]:
    """The friction levels hypothesis ``h`` set out to fit that :func:`full_fit` held, and why."""
    out = []
    for p in model.params:
        if p.name in h.free and p.name in LAW_PARAMS[model.law] and not p.free:
            why = ('it ended on its bound, or within two standard errors of zero' if p.name == 'Fc'
                   else 'the refit put it on a bound')
            out.append(f'{p.name} held at {p.value:.4g} {p.unit}: the data do not determine it ({why})')
    return out


def _alternative(j: Judged, pv: Problem) -> dict:
    return {'hypothesis': j.h.label, 'validation_x_rms_counts': pv.summary(j.model)['x_rms_counts'],
            'validation_gain_percent': j.gain, 'refused': j.refused}


def refit_notes(declared: Model, model: Model) -> list[str]:
    """A declared friction value the refit moved by more than REFIT_NOTE."""
    out = []
    for p in model.free:
        if p.name not in FRICTION_FITTED or not any(q.name == p.name for q in declared.params):
            continue
        old = declared[p.name]
        if abs(p.value - old) > REFIT_NOTE * max(abs(old), PARAMS[p.name].typical):
            out.append(f'{p.name} refitted from {old:.4g} to {p.value:.4g} {p.unit} '
                       f'({100 * (p.value - old) / (abs(old) or 1):+.0f} %)')
    return out
