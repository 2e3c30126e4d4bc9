"""Residual analysis: the signatures of effects in a force residual.

All functions take the residual r [N] of the force balance on the samples used in the
fit, with the signals at the same samples. A signature score is the share of the
residual's variance (0..1) that one variable explains, by the means of r in bins of
that variable (the correlation ratio eta^2), or by a spectral peak for the position.
"""
from __future__ import annotations

import numpy as np

__all__ = ['time_since_reversal', 'SIGNATURES', 'signature_scores']

MAX_LAG = 25
BINS = 20


def cross_correlation(r: np.ndarray, u: np.ndarray, max_lag: int = MAX_LAG) -> np.ndarray:
    """Normalized cross-correlation of r(t) with u(t - k), k = -max_lag..max_lag."""
    r = np.asarray(r, float) - np.mean(r)
    u = np.asarray(u, float) - np.mean(u)
    den = float(np.sqrt((r @ r) * (u @ u))) or 1.0
    n = len(r)
    out = []
    for k in range(-max_lag, max_lag + 1):
        out.append(float(r[k:] @ u[:n - k]) / den if k >= 0 else float(r[:n + k] @ u[-k:]) / den)
    return np.array(out)


def eta_squared(r: np.ndarray, var: np.ndarray, bins: int = BINS) -> float:
    """Share of var(r) explained by the means of r in quantile bins of ``var``."""
    r = np.asarray(r, float)
    total = float(np.var(r))
    if total == 0.0 or np.ptp(var) == 0.0:
        return 0.0
    edges = np.unique(np.quantile(var, np.linspace(0, 1, bins + 1)))
    idx = np.clip(np.searchsorted(edges, var, side='right') - 1, 0, len(edges) - 2)
    means = np.bincount(idx, r, len(edges) - 1) / np.maximum(np.bincount(idx, minlength=len(edges) - 1), 1)
    return float(np.var(means[idx]) / total)


def position_spectrum(r: np.ndarray, x: np.ndarray, n_grid: int = 512):
    """(periods [m], power) of r as a function of position (a ripple fixed to the track).

    r is averaged in position bins over the travelled range, then Fourier analysed.
    """
    lo, hi = float(np.min(x)), float(np.max(x))
    if hi - lo <= 0:
        return np.array([]), np.array([])
    edges = np.linspace(lo, hi, n_grid + 1)
    idx = np.clip(np.searchsorted(edges, x, side='right') - 1, 0, n_grid - 1)
    cnt = np.bincount(idx, minlength=n_grid)
    prof = np.bincount(idx, r, n_grid) / np.maximum(cnt, 1)
    filled = cnt > 0
    prof = np.interp(np.arange(n_grid), np.nonzero(filled)[0], prof[filled]) - prof[filled].mean()
    spec = np.abs(np.fft.rfft(prof * np.hanning(n_grid))) ** 2
    freq = np.fft.rfftfreq(n_grid, (hi - lo) / n_grid)
    return 1.0 / freq[2:], spec[2:]


def position_score(r, x) -> tuple[float, float | None]:
    """(share of the position spectrum in its largest peak, that peak's period [m])."""
    periods, spec = position_spectrum(r, x)
    if len(spec) < 3 or spec.sum() == 0:
        return 0.0, None
    k = int(np.argmax(spec))
    return float(spec[max(k - 1, 0):k + 2].sum() / spec.sum()), float(periods[k])


def time_since_reversal(t: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Seconds since x' last changed sign (the first stretch counts from t[0])."""
    s = np.sign(v)
    rev = np.nonzero(s[1:] * s[:-1] < 0)[0] + 1
    last = np.zeros(len(t))
    for k in rev:
        last[k:] = t[k]
    last[:rev[0] if len(rev) else len(t)] = t[0]
    return t - last


def best_lag(r: np.ndarray, du: np.ndarray, dt: float, max_lag: int = MAX_LAG) -> tuple[float, float]:
    """(largest |correlation| of r with the input rate over lags >= 0, that lag [s])."""
    c = cross_correlation(r, du, max_lag)[max_lag:]
    k = int(np.argmax(np.abs(c)))
    return float(abs(c[k])), k * dt


SIGNATURES = {
    'velocity_sign': 'sgn(x\')', 'speed': '|x\'| (by direction)', 'reversal': 'time since reversal',
    'direction': '|x\'| unsigned (even in x\')', 'mean': 'constant', 'position': 'position (spectrum)',
    'voltage': 'input u', 'lag': 'lag to the input rate', 'pendulum_mean': 'pendulum-equation mean',
}


def signature_scores(r, t, x, v, u, dt, pendulum_residual=None) -> dict:
    """Score in 0..1 of each signature of :data:`SIGNATURES` on the residual r."""
    s = np.sign(v)
    ms = float(np.mean(r ** 2)) or 1.0
    pos, period = position_score(r, x)
    lag_corr, lag = best_lag(r, np.gradient(u), dt)
    rev = time_since_reversal(t, v)
    out = {
        'velocity_sign': eta_squared(r, s, 2),
        'speed': eta_squared(r * s, np.abs(v)),
        'reversal': eta_squared(r * s, np.minimum(rev, 0.5)),
        'direction': eta_squared(r, np.abs(v)),
        'mean': float(np.mean(r) ** 2 / ms),
        'position': pos,
        'voltage': eta_squared(r, u),
        'lag': lag_corr ** 2,
        'pendulum_mean': 0.0,
    }
    if pendulum_residual is not None and len(pendulum_residual):
        out['pendulum_mean'] = float(np.mean(pendulum_residual) ** 2 / (np.mean(pendulum_residual ** 2) or 1.0))
    return {'scores': out, 'position_period_m': period, 'lag_s': lag}
