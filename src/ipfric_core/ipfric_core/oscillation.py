"""Oscillation analysis of a sampled run: settled, limit cycle, growing or fallen.

Works on plain arrays (time [s], cart position [m], angle [rad]), whatever produced
them: the offline closed loop, or a bag read back from a ROS run.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from scipy.ndimage import maximum_filter1d, minimum_filter1d

CLASSES = ('settled', 'limit_cycle', 'growing', 'fallen')


@dataclass
class Oscillation:
    """Result of :func:`classify`.

    cls : one of CLASSES
    transition_time : s; when the final regime starts (entry into the settled band,
        onset of the cycle, or the fall); None while still converging
    x_p2p, theta_p2p : peak-to-peak over the analysis window [m], [rad]
    period_crossings, period_spectrum : s, two independent estimates (None if no cycle)
    frequency : Hz, from the zero-crossing period
    stick_fraction : share of the window with the cart at rest (encoder plateaus)
    """

    cls: str
    transition_time: float | None
    x_p2p: float
    theta_p2p: float
    period_crossings: float | None
    period_spectrum: float | None
    frequency: float | None
    stick_fraction: float
    window: tuple

    def to_dict(self) -> dict:
        return asdict(self)


def crossing_period(t: np.ndarray, y: np.ndarray) -> float | None:
    """Mean period [s] from upward crossings of the mean (linear interpolation)."""
    y = y - y.mean()
    idx = np.nonzero((y[:-1] < 0) & (y[1:] >= 0))[0]
    if len(idx) < 2:
        return None
    tc = t[idx] - y[idx] * (t[idx + 1] - t[idx]) / (y[idx + 1] - y[idx])
    return float(np.mean(np.diff(tc)))


def spectral_period(t: np.ndarray, y: np.ndarray) -> float | None:
    """Period [s] of the largest spectral peak (Hann window, parabolic peak interpolation)."""
    n = len(y)
    if n < 16:
        return None
    dt = float(np.median(np.diff(t)))
    y = (y - y.mean()) * np.hanning(n)
    pad = 1 << int(math.ceil(math.log2(n)) + 2)
    spec = np.abs(np.fft.rfft(y, pad))
    spec[0] = 0.0
    k = int(np.argmax(spec))
    if k < 1 or k >= len(spec) - 1 or spec[k] == 0:
        return None
    a, b, c = np.log(spec[k - 1:k + 2] + 1e-300)
    shift = 0.5 * (a - c) / (a - 2 * b + c) if (a - 2 * b + c) != 0 else 0.0
    f = (k + shift) / (pad * dt)
    return float(1.0 / f) if f > 0 else None


def classify(t, x, theta, resolution=(4.54e-5, 1.534e-3), fallen_angle: float = math.radians(30.0),
             ended_fallen: bool = False, window: float = 10.0) -> Oscillation:
    """Classify a run from its samples.

    Settled: over the last ``window`` seconds both signals stay inside a band of
    2 encoder counts (``resolution`` = (cart [m], angle [rad]); a count is taken as at
    least 5e-5, so exact sensors settle inside 0.1 mm and 0.006 deg) about
    their mean.
    The larger of the two signals (in counts) then decides: growing if the second half
    of the window has over 1.25 times the peak-to-peak of the first; settled (still
    converging) if it has under half, or if the signal does not cross its mean twice
    (a creep, not an oscillation); otherwise a limit cycle. Fallen: |theta| reached ``fallen_angle``, or the run ended on a
    safety limit (``ended_fallen``: the pendulum fell or the cart hit the track end).
    """
    t, x, theta = (np.asarray(a, float) for a in (t, x, theta))
    over = np.nonzero(np.abs(theta) >= fallen_angle)[0]
    if ended_fallen or len(over):
        tf = float(t[over[0]]) if len(over) else float(t[-1])
        return Oscillation('fallen', tf, float(np.ptp(x)), float(np.ptp(theta)), None, None, None,
                           0.0, (float(t[0]), float(t[-1])))
    w = t >= t[-1] - window
    xs, ths, ts = x[w], theta[w], t[w]
    xp, thp = float(np.ptp(xs)), float(np.ptp(ths))
    steps = np.diff(xs) == 0.0
    stick = float(steps.mean()) if len(steps) else 0.0
    band_x, band_th = 2 * max(resolution[0], 5e-5), 2 * max(resolution[1], 5e-5)
    if xp <= band_x and thp <= band_th:
        outside = (np.abs(x - xs.mean()) > band_x) | (np.abs(theta - ths.mean()) > band_th)
        last = np.nonzero(outside)[0]
        tt = float(t[last[-1] + 1]) if len(last) and last[-1] + 1 < len(t) else float(t[0])
        return Oscillation('settled', tt, xp, thp, None, None, None, stick, (float(ts[0]), float(ts[-1])))
    signal = ths if thp / band_th >= xp / band_x else xs
    half = len(signal) // 2
    first, second = float(np.ptp(signal[:half])), float(np.ptp(signal[half:]))
    pc, ps = crossing_period(ts, signal), spectral_period(ts, signal)
    window_span = (float(ts[0]), float(ts[-1]))
    if second > 1.25 * first:
        cls = 'growing'
    elif second < 0.5 * first or pc is None:
        # decaying, or a creep without oscillation: converging to rest
        return Oscillation('settled', None, xp, thp, None, None, None, stick, window_span)
    else:
        cls = 'limit_cycle'
    onset = _onset(t, x, 0.5 * xp, 1.5 * (pc or ps or 1.0))
    return Oscillation(cls, onset, xp, thp, pc, ps, 1.0 / pc if pc else None, stick, window_span)


def window_ptp(x: np.ndarray, n: int) -> np.ndarray:
    """Peak-to-peak of every window x[i:i+n], i = 0 .. len(x) - n, in O(len(x))."""
    x = np.asarray(x, float)
    full = maximum_filter1d(x, n) - minimum_filter1d(x, n)   # centred windows
    return full[n // 2:n // 2 + len(x) - n + 1]


def _onset(t, x, half_p2p, span) -> float:
    """First time after which the cart's envelope over ``span`` [s] stays above half the final p2p."""
    dt = float(np.median(np.diff(t)))
    n = max(1, int(round(span / dt)))
    if len(x) <= n:
        return float(t[0])
    env = window_ptp(x, n)
    low = np.nonzero(env < half_p2p)[0]
    return float(t[low[-1] + n]) if len(low) and low[-1] + n < len(t) else float(t[0])
