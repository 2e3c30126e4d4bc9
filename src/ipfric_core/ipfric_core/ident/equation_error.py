"""The cart's force balance by equation error: what starts the ladder on a force-input record that
declares no plant, the force error of a model, and the signatures of what a model leaves.

Equation error on filtered derivatives: position and input are low-pass filtered with
a zero-phase Butterworth filter (corner ``Record.cutoff_hz``), differentiated, and
decimated to five samples per corner period. The force balance of
:mod:`ipfric_core.ident.effects` is fitted by bounded nonlinear least squares
(``scipy.optimize.least_squares``, trust region reflective); the standard errors come
from the Jacobian at the optimum. Samples with |x'| below ``Record.stick_velocity``
(the cart held by static friction: the friction force there is unknown), widened by one
corner period, and the filter's start-up at both ends are left out of the force balance;
static friction enters as inequalities on the stretches where the encoder stands still
(held force <= Fs while stuck, >= Fs at the breakaway). With the pendulum, its own
equation (no unknown parameter) is a further residual block.

:func:`base_fit` fits a friction law's force balance (mass, viscous slope, the law's levels);
:func:`force_error` is the relative force error of a model (the EMPS benchmark's metric);
:func:`signatures_left` scores the model's force residual against the signatures of
:mod:`ipfric_core.ident.residual` (what the residual follows: the direction of motion, the
position, the input, ...).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares
from scipy.signal import butter, sosfiltfilt

from ..analysis.records import Record, filtered_on_grid, uneven
from ..physics.params import ConfigError
from ..physics.plant import held_forces, pendulum_residuals, required_forces
from . import effects as fx
from .residual import signature_scores

__all__ = ['Prepared', 'balance', 'parts', 'base_fit', 'structure_fit', 'force_error', 'signatures_left',
           'identify_steady']

EDGE_S = 0.15
TICK_S = 0.02
STUCK_S = 0.05  # an encoder standing still this long [s] shows a stuck cart


class Prepared:
    """Filtered, differentiated and decimated signals of one record."""

    def __init__(self, rec: Record):
        self.rec = rec
        dt = rec.dt
        fs = 1.0 / dt
        cutoff = min(rec.cutoff_hz, 0.4 * fs)
        self.sos = butter(4, cutoff, fs=fs, output='sos')
        self.q = max(1, int(fs / (5 * cutoff)))
        t = rec.t
        n = len(t)
        self.idx = np.arange(0, n, self.q)
        self.dt = dt * self.q
        self.t_full = t
        #: the stamps are uneven: signals are filtered on a uniform grid (:meth:`smooth_derivatives`)
        self.uneven = uneven(t)
        # the command u_k is held over [t_k, t_k+1): at t_k the force is the mean of u_k-1 and u_k
        self.u_full = np.concatenate([[rec.u[0]], 0.5 * (rec.u[1:] + rec.u[:-1])])
        self.t = t[self.idx]
        self.u_raw = rec.u[self.idx]
        self.x, self.v, self.a = self._derivatives(rec.x)
        D = fx.dwell_profile(t, rec.x)
        self.Dx, self.Dv, self.Da = (0.5 * s for s in self._derivatives(D))
        self.has_theta = rec.theta is not None
        if self.has_theta:
            self.th, self.thd, self.thdd = self._derivatives(rec.theta)
        self.uf_full = self.smooth(self.u_full)
        self.uf = self.uf_full[self.idx]
        self._breakaways(rec)
        self.inside = (self.t >= t[0] + EDGE_S) & (self.t <= t[-1] - EDGE_S)
        self.used = self.inside & ~self.near(np.abs(self.v) < rec.stick_velocity)
        if self.used.sum() < 50:
            raise ConfigError(f'{rec.name}: only {int(self.used.sum())} moving samples (|x\'| >= '
                              f'{rec.stick_velocity:g} m/s); the data hardly move the axis')
        self.n_used = int(self.used.sum())
        #: encoder count [m] (a play below two counts is quantization)
        self.resolution = rec.x_resolution
        self.vmax = float(np.quantile(np.abs(self.v[self.used]), 0.95))

    def _breakaways(self, rec: Record) -> None:
        """Samples where the encoder shows a stuck cart (every q-th sample of the stretches of at
        least STUCK_S) and the breakaways that end them; the pendulum state there."""
        self.b_idx = np.zeros(0, int)
        self.b_kind = np.zeros(0)
        if rec.stick_velocity <= 0:
            return
        t = rec.t
        idx, kind = [], []
        for a, b in fx.plateaus(t, rec.x, STUCK_S):
            if t[a] < t[0] + EDGE_S or t[b] > t[-1] - EDGE_S:
                continue
            # the cart creeps within one count before it stops and after it breaks away: leave
            # TICK_S at both ends of the stretch out
            m = int(round(TICK_S / rec.dt))
            held = list(range(a + m, b - m, self.q))
            idx += held + [b]
            kind += [1.0] * len(held) + [-1.0]
        self.b_idx = np.array(idx, int)
        self.b_kind = np.array(kind)
        self.b_x = rec.x[self.b_idx]
        if rec.theta is not None:
            f, v = self.smooth_derivatives(rec.theta, rec.valid_mask, 1)
            self.b_th, self.b_thd = f[self.b_idx], v[self.b_idx]

    def near(self, stuck: np.ndarray) -> np.ndarray:
        """``stuck`` widened by one corner period each side (the filter spreads a stick-slip
        transition over about that much time)."""
        k = max(1, int(round(1.0 / (self.rec.cutoff_hz * self.dt))))
        if not stuck.any():
            return stuck
        return np.convolve(stuck.astype(float), np.ones(2 * k + 1), 'same') > 0

    def smooth(self, y: np.ndarray) -> np.ndarray:
        """``y`` (a command: every sample valid) low-passed without phase, at the stamps
        (:meth:`smooth_derivatives`)."""
        return self.smooth_derivatives(y, None, 0)[0]

    def smooth_derivatives(self, y: np.ndarray, valid: np.ndarray | None, derivatives: int) -> list[np.ndarray]:
        """``y`` low-passed without phase and its first ``derivatives`` time derivatives [unit/s^k], at the
        stamps. Where they are uneven, on a uniform grid of the median period, its ``valid`` samples read off
        linearly (:func:`~ipfric_core.analysis.records.filtered_on_grid`): a filter run over uneven samples as
        if they were even, then differenced over the true stamps, made the derivatives noise (a cart logged
        at 1.3-12.6 ms, median 3.6 ms: its force balance left 9 N RMS against a drive force of 2 N)."""
        if self.uneven:
            return filtered_on_grid(self.rec.t, y, self.sos, valid, derivatives)
        out = [sosfiltfilt(self.sos, y)]
        for _ in range(derivatives):
            out.append(np.gradient(out[-1], self.rec.t))
        return out

    def _derivatives(self, y):
        return tuple(s[self.idx] for s in self.smooth_derivatives(y, self.rec.valid_mask, 2))


@dataclass
class Balance:
    """Force balance at the decimated samples: input force y, model force, residual, weights."""

    y: np.ndarray
    model: np.ndarray
    r: np.ndarray
    used: np.ndarray
    pendulum: np.ndarray | None
    x: np.ndarray
    v: np.ndarray
    u: np.ndarray
    static: np.ndarray  # violations of static friction [N]: stuck |held| > Fs or breakaway |held| < Fs


def balance(pr: Prepared, p: dict, active) -> Balance:
    """Evaluate the force balance of :mod:`effects` with parameters ``p``."""
    rec = pr.rec
    if any(fx.EFFECTS[e].acts_on == 'input' for e in active):
        u = fx.effective_input(pr.t_full, pr.u_full, p, active)
        uf_full = pr.smooth(u)
    else:
        uf_full = pr.uf_full
    uf = uf_full[pr.idx]
    gain = p.get('alpha', rec.gain)
    y = gain * uf
    x, v, a = pr.x, pr.v, pr.a
    if 'backlash' in active:
        g = p['backlash_m']
        x, v, a = x + g * pr.Dx, v + g * pr.Dv, a + g * pr.Da
    pp = fitted_plant_vector(rec, p)
    th = pr.th - p.get('bias_theta_rad', 0.0) if pr.has_theta else np.zeros_like(a)
    thd = pr.thd if pr.has_theta else np.zeros_like(a)
    model = required_forces(pp, a, th, thd) + pp[5] * v + fx.resisting_force(x, v, p, active, pr.dt)
    pend = pendulum_residuals(pp, a, th, pr.thdd) if pr.has_theta else None
    used = pr.used
    static = np.zeros(0)
    if len(pr.b_idx):
        # held force: input less the pendulum's reaction and the track forces, with the cart at rest
        # (filtered like the rest: a command spike too short to move the cart past one count is
        # smoothed as the cart's inertia smooths it)
        held = gain * uf_full[pr.b_idx] - fx.position_force(pr.b_x, p, active)
        if pr.has_theta:
            held = held_forces(pp, pr.b_th - p.get('bias_theta_rad', 0.0), pr.b_thd, held)
        # stuck: static friction held it, held within the static levels; breakaway: beyond them (eq. 5)
        back, fwd = fx.static_levels(p, active)
        static = np.maximum(0.0, pr.b_kind * np.where(held >= 0.0, held - fwd, -held - back))
        if 'backlash' in active:  # a cart crossing the play moves while its encoder stands still
            static = np.where(np.abs(v[np.minimum(pr.b_idx // pr.q, len(v) - 1)]) >= rec.stick_velocity,
                              0.0, static)
    return Balance(y, model, np.where(used, y - model, 0.0), used, pend, x, v, uf, static)


def fitted_plant_vector(rec: Record, p: dict) -> tuple:
    """The plant vector of :mod:`ipfric_core.physics.plant` with the fitted mass: (M, m, l, g,
    gain, back-EMF; the record's unless ``p`` holds alpha and beta), the pendulum's (m, l, g) when
    attached, else m = 0."""
    m, l, g = rec.pendulum if rec.pendulum is not None else (0.0, 1.0, 9.8)
    return (float(p['M']), float(m), float(l), float(g), float(p.get('alpha', rec.gain)),
            float(p.get('beta', rec.back_emf)))


def residual_vector(pr: Prepared, p: dict, active) -> np.ndarray:
    b = balance(pr, p, active)
    parts = [b.r, b.static]
    if b.pendulum is not None:
        parts.append(np.where(pr.inside, b.pendulum, 0.0))
    return np.concatenate(parts)


def param_specs(active) -> list:
    return [fx.PARAMS[n] for n in fx.BASE_PARAMS] + [s for e in active for s in fx.EFFECTS[e].specs]


@dataclass
class Fit:
    active: tuple
    params: dict
    std: dict
    cost: float        # mean squared residual [N^2] over the used samples (+ pendulum block)


def fit(pr: Prepared, active, start: dict, held: dict | None = None) -> Fit:
    """Bounded least squares of all parameters of ``active`` from ``start``, but those of ``held``: held at
    their values there (a declared mass)."""
    held = held or {}
    specs = [s for s in param_specs(active) if s.name not in held]
    names = [s.name for s in specs]
    umax = float(np.max(np.abs(pr.u_full)))
    # input effects may not switch the input off: a deadzone below half, a limit above a third of max |u|
    lo = np.array([0.3 * umax if s.name == 'saturation_V' else fx.lower_bound(s.name, active) for s in specs])
    hi = np.array([0.5 * umax if s.name == 'deadzone_V' else s.hi for s in specs])
    x0 = np.clip(np.array([start[nm] for nm in names], float), lo + 1e-12 * (hi - lo), hi - 1e-12 * (hi - lo))

    def fun(theta):
        return residual_vector(pr, {**held, **dict(zip(names, theta))}, active)
    sol = least_squares(fun, x0, bounds=(lo, hi), x_scale='jac', max_nfev=200, method='trf')
    r = sol.fun
    n = pr.n_used + len(pr.b_idx) + (pr.inside.sum() if pr.has_theta else 0)
    dof = max(1, n - len(names))
    J = sol.jac
    try:
        norm = np.linalg.norm(J, axis=0)
        scale = np.where(norm > 0, norm, 1.0)
        Js = J / scale  # columns of unit norm: the parameters' units differ by many decades
        cov = np.linalg.pinv(Js.T @ Js) / np.outer(scale, scale) * float(r @ r) / dof
        std = np.sqrt(np.maximum(np.diag(cov), 0.0))
        std[np.linalg.norm(J, axis=0) == 0.0] = np.nan  # the data say nothing about it
    except np.linalg.LinAlgError:
        std = np.full(len(names), np.nan)
    p = {**held, **dict(zip(names, map(float, sol.x)))}
    return Fit(tuple(active), p, dict(zip(names, map(float, std))), float(r @ r) / n)


def starts(pr: Prepared, name: str, p: dict, active) -> list[dict]:
    """Start values of effect ``name``'s parameters (several for the nonlinear ones)."""
    b = balance(pr, p, active)
    sig = signature_scores(b.r[b.used], pr.t[b.used], b.x[b.used], b.v[b.used], b.u[b.used], pr.dt)
    base = dict.fromkeys(fx.EFFECTS[name].params, 0.0)
    u_scale = float(np.std(pr.u_full)) or 1.0
    options = {
        'stribeck': [{'v_s': f * pr.vmax} for f in (0.05, 0.2, 0.6)],
        'coulomb': [{'Fc': 0.0, 'Fs_excess': 0.0}],
        'presliding': [{'sigma0': max(p.get('Fc', 1.0), 1e-3) / z} for z in (1e-2, 1e-3, 1e-4, 1e-5)],
        'cogging': [{'cogging_period_m': sig['position_period_m'] or 0.01}],
        'deadzone': [{'deadzone_V': f * u_scale} for f in (0.02, 0.1, 0.3)],
        'saturation': [{'saturation_V': f * float(np.max(np.abs(pr.u_full)))} for f in (0.6, 0.8, 0.95)],
        'backlash': [{'backlash_m': g} for g in (1e-4, 1e-3, 3e-3, 1e-2)],
        'delay': [{'input_delay_s': d} for d in sorted({sig['lag_s'], *np.geomspace(1e-3, 0.2, 10).tolist()})],
    }.get(name, [{}])
    return [{**p, **base, **o} for o in options]


def best_fit(pr: Prepared, active, candidates: list[dict], held: dict | None = None) -> Fit:
    """Fit from the start with the lowest initial cost (and from the best two if several)."""
    costs = [float(np.mean(residual_vector(pr, c, active) ** 2)) for c in candidates]
    order = np.argsort(costs)[:2]
    fits = [fit(pr, active, candidates[i], held) for i in order]
    return min(fits, key=lambda f: f.cost)


def errors(pr: Prepared, p: dict, active) -> dict:
    """RMS [N] and relative error [%] = 100 ||F - F_model|| / ||F|| on the used samples."""
    b = balance(pr, p, active)
    r, y = b.r[b.used], b.y[b.used]
    return {'rms': float(np.sqrt(np.mean(r ** 2))), 'relative_percent': float(100 * np.linalg.norm(r) /
                                                                                 (np.linalg.norm(y) or 1.0)),
            'samples': int(b.used.sum())}


def base_fit(rec: Record, law: str, mass: float | None = None, pr: Prepared | None = None) -> Fit:
    """The force balance of friction law ``law`` (a key of :data:`~ipfric_core.ident.effects.BASE_MODELS`)
    fitted to ``rec``: the mass (held at ``mass`` [kg] when given: a declared plant), the viscous slope
    and the law's levels; viscous first (linear in them: the start of the rest), then each part of the
    law in turn from its starts (:func:`starts`). ``pr``: ``rec`` already prepared."""
    if law not in fx.BASE_MODELS:
        raise ConfigError(f'base model: {law!r} is not one of {", ".join(fx.BASE_MODELS)}')
    pe = pr or Prepared(rec)
    active = fx.BASE_MODELS[law]
    held = {} if mass is None else {'M': float(mass)}
    start = dict(fit(pe, (), {'M': 1.0, 'eps': 0.0}, held).params)
    for k, e in enumerate(active):
        start = best_fit(pe, active[:k + 1], starts(pe, e, start, active[:k]), held).params
    return fit(pe, active, start, held)


def parts(law: str, effects) -> tuple:
    """A model's friction law and effects as the force balance's active parts (a drive with play has a
    hidden state the balance cannot express: left out)."""
    return fx.BASE_MODELS[law] + tuple(e for e in effects if fx.EFFECTS[e].acts_on != 'drive')


def structure_fit(rec: Record, p: dict, law: str, effects) -> Fit:
    """The force balance of a model's structure (its friction law and effects: :func:`parts`) fitted to
    ``rec`` from the model's values ``p``: the mass, the law's levels and the effects' parameters."""
    return fit(Prepared(rec), parts(law, effects), p)


def force_error(rec: Record, p: dict, law: str, effects) -> dict:
    """RMS [N] and relative error [%] = 100 ||F - F_model|| / ||F|| of a model's force balance on ``rec``
    (its values ``p`` by name, its friction law and effects: :func:`parts`)."""
    return errors(Prepared(rec), p, parts(law, effects))


def signatures_left(rec: Record, p: dict, law: str, effects) -> dict:
    """What a model's force residual on ``rec`` follows: the share of its variance (0..1) each signature
    of :data:`~ipfric_core.ident.residual.SIGNATURES` explains, the residual's RMS [N] and its relative size
    (:func:`force_error`); with the period of a position signature [m] and the lag of an input one [s]."""
    active = parts(law, effects)
    pr = Prepared(rec)
    b = balance(pr, p, active)
    u = b.used
    sig = signature_scores(b.r[u], pr.t[u], b.x[u], b.v[u], b.u[u], pr.dt,
                           None if b.pendulum is None else b.pendulum[pr.inside])
    return {**sig, **errors(pr, p, active)}


def identify_steady(plant, volts, vels, breakaway_volts) -> dict:
    """The cart-alone appendix experiments through the same force balance.

    Steady sliding (Table 5, x'' = 0): alpha V = (beta + eps) v + Fc, the coulomb effect's
    sliding branch; breakaway on a ramp (Table 6): alpha V_s = Fs = Fc + Fs_excess, its static
    branch. One bounded least-squares fit of (eps, Fc, Fs_excess) with standard errors;
    F_N = M g. The residual of the sliding rows is returned against velocity.
    """
    V, v, Vs = (np.asarray(a, float) for a in (volts, vels, breakaway_volts))
    active = ('coulomb',)

    def fun(theta):
        p = {'eps': theta[0], 'Fc': theta[1], 'Fs_excess': theta[2]}
        slide = plant.alpha * V - plant.beta * v - fx.resisting_force(np.zeros_like(v), v, p, active, 1.0)
        return np.concatenate([slide, plant.alpha * Vs - fx.static_levels(p, active)[1]])
    sol = least_squares(fun, [1.0, 0.1, 0.1], bounds=([0, 0, 0], [1e3, 1e3, 1e3]))
    r = sol.fun
    cov = np.linalg.inv(sol.jac.T @ sol.jac) * float(r @ r) / max(1, len(r) - 3)
    std = np.sqrt(np.diag(cov))
    fn = plant.M * plant.g
    rs = r[:len(v)]
    return {'eps': float(sol.x[0]), 'eps_std': float(std[0]),
            'mu_c': float(sol.x[1] / fn), 'mu_c_std': float(std[1] / fn),
            'mu_s': float((sol.x[1] + sol.x[2]) / fn), 'mu_s_std': float(np.hypot(std[1], std[2]) / fn),
            'sliding_residual_N': rs.tolist(), 'velocity_mps': v.tolist(),
            'sliding_rms_N': float(np.sqrt(np.mean(rs ** 2))),
            'breakaway_rms_N': float(np.sqrt(np.mean(r[len(v):] ** 2))),
            'residual_velocity_correlation': float(np.corrcoef(rs, v)[0, 1]),
            'residual_curvature_N': float(np.polyfit(v, rs, 2)[0] * np.ptp(v) ** 2 / 4)}
