"""Critical feedback delay of the linearized delayed loop y' = A y + E y(t - tau), eq. (27).

With E = B K (the delayed control, eq. 26) and A the open loop with the undelayed
motor damping beta, a root lambda = i omega exists when
det(i omega I - A - E mu) = 0 with mu = exp(-i omega tau), |mu| = 1.
For each omega the admissible mu are the finite generalized eigenvalues of the pencil
(i omega I - A, E); tau_c is the smallest tau > 0 over all crossings |mu(omega)| = 1.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg
from scipy.optimize import brentq

__all__ = ['gain_critical_delay']


def _mus(A, E, w) -> np.ndarray:
    n = A.shape[0]
    alpha, beta = scipy.linalg.eig(1j * w * np.eye(n) - A, E, right=False, homogeneous_eigvals=True)
    finite = np.abs(beta) > 1e-12 * np.abs(alpha).max()
    return np.sort_complex(alpha[finite] / beta[finite])


def critical_delay(A, E, omega_max: float = 200.0, n_grid: int = 20000) -> dict:
    """Smallest delay tau_c [s] at which a root of (27) reaches the imaginary axis.

    Returns {'tau_c', 'omega' [rad/s], 'frequency_hz'}; tau_c = 0 when A + E is not
    Hurwitz, None when no crossing exists below ``omega_max``.
    """
    A, E = np.asarray(A, float), np.asarray(E, float)
    eig0 = np.linalg.eigvals(A + E)
    # a zero eigenvalue shared by every tau (the dynamic model's z - x line) is ignored
    if np.any(eig0.real > 1e-9):
        return {'tau_c': 0.0, 'omega': None, 'frequency_hz': None}
    omegas = np.linspace(omega_max / n_grid, omega_max, n_grid)
    best = None
    prev = None
    for w in omegas:
        mags = np.abs(_mus(A, E, w)) - 1.0
        if prev is not None and len(mags) == len(prev[1]):
            for k in np.nonzero(np.sign(mags) != np.sign(prev[1]))[0]:
                wc = brentq(lambda ww, k=k: np.abs(_mus(A, E, ww))[k] - 1.0, prev[0], w, xtol=1e-12)
                mu = _mus(A, E, wc)[k]
                tau = np.mod(-np.angle(mu), 2 * np.pi) / wc
                if best is None or tau < best[0]:
                    best = (tau, wc)
        prev = (w, mags)
    if best is None:
        return {'tau_c': None, 'omega': None, 'frequency_hz': None}
    return {'tau_c': float(best[0]), 'omega': float(best[1]), 'frequency_hz': float(best[1] / (2 * np.pi))}


def delayed_system(A, B, gain):
    """(A, E) of eq. (27): E = B K applies the delayed state (eqs. 29, 32)."""
    B = np.asarray(B, float).reshape(-1, 1)
    return np.asarray(A, float), B @ np.asarray(gain, float).reshape(1, -1)


def gain_critical_delay(A, B, gain, **grid) -> dict:
    """:func:`critical_delay` of the gain K [V per state unit] on (A, B) (``grid``: its
    ``omega_max``, ``n_grid``); K is padded with zeros for the states it does not feed back
    (the bristle state z of the dynamic law)."""
    n = np.asarray(A).shape[0]
    return critical_delay(*delayed_system(A, B, list(gain) + [0.0] * (n - len(gain))), **grid)
