"""Linear stability of the upright equilibrium: eigenvalues, Routh-Hurwitz (paper eq. 19)
and the smoothing slope delta at which the old gain loses stability (section 3.1).
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from ..physics.params import FrictionParams, PlantParams
from .linearize import characteristic_coefficients

__all__ = ['delta_thresholds']


def routh_first_column(coeffs) -> np.ndarray:
    """First column of the Routh array of a polynomial [a_n, ..., a_0] (a_n > 0).

    A zero pivot is replaced by a small epsilon (the usual limiting argument).
    """
    c = np.asarray(coeffs, float)
    n = len(c)
    rows = [c[0::2].copy(), c[1::2].copy()]
    width = len(rows[0])
    rows = [np.pad(r, (0, width - len(r))) for r in rows]
    for _ in range(n - 2):
        a, b = rows[-2], rows[-1]
        pivot = b[0] if b[0] != 0 else 1e-12 * max(1.0, np.abs(c).max())
        new = np.zeros(width)
        for j in range(width - 1):
            new[j] = (pivot * a[j + 1] - a[0] * b[j + 1]) / pivot
        rows.append(new)
    return np.array([r[0] for r in rows])


def rhp_root_count(coeffs) -> int:
    """Number of roots with positive real part: sign changes in the Routh first column."""
    col = routh_first_column(coeffs)
    signs = np.sign(col[col != 0])
    return int(np.sum(signs[1:] != signs[:-1]))


def delta_thresholds(plant: PlantParams, friction: FrictionParams, gain,
                     delta_max: float = 1e4) -> dict:
    """Slopes delta of tanh(delta v) where the closed loop of eq. (19) changes.

    Returns ``unstable_above``: the delta beyond which two roots lie in the right half
    plane (Routh-Hurwitz), and ``complex_until``: the delta beyond which that pair is
    real (no longer oscillatory), each found by bisection to 1e-6 relative.
    """
    def coeffs(d):
        return characteristic_coefficients(plant, friction.replace(delta=d), gain)

    def rhp(d):
        return rhp_root_count(coeffs(d))

    grid = np.geomspace(1e-2, delta_max, 400)
    counts = [rhp(d) for d in grid]
    i = next((k for k, n in enumerate(counts) if n > 0), None)
    if i is None:
        return {'unstable_above': None, 'complex_until': None, 'rhp_roots': 0}
    lo, hi = grid[i - 1], grid[i]
    while hi - lo > 1e-7 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if rhp(mid) > 0 else (mid, hi)
    unstable = hi

    def rhp_imag(d):
        r = np.roots(coeffs(d))
        return np.abs(r[r.real > 0].imag).max(initial=0.0)

    complex_until = None
    grid2 = np.geomspace(unstable * 1.0001, delta_max, 400)
    j = next((k for k, d in enumerate(grid2) if rhp_imag(d) < 1e-9), None)
    if j is not None and j > 0:
        complex_until = brentq(lambda d: _disc(coeffs(d)), grid2[j - 1], grid2[j], xtol=1e-9)
    return {'unstable_above': unstable, 'complex_until': complex_until, 'rhp_roots': counts[i]}


def _disc(coeffs) -> float:
    """Signed measure that vanishes when the right-half-plane pair turns real.

    Positive while the pair is complex: the imaginary part; negative once real: minus
    the gap between the two right-half-plane real roots.
    """
    r = np.roots(coeffs)
    rr = r[r.real > 0]
    if np.abs(rr.imag).max(initial=0.0) > 0:
        return float(np.abs(rr.imag).max())
    return -float(np.ptp(rr.real)) if len(rr) > 1 else -1.0
