"""Oscillation analysis of a sampled run: settled, limit cycle, growing or fallen.

Works on plain arrays (time [s], cart position [m], angle [rad]), whatever produced
them: the offline closed loop, or a bag read back from a ROS run.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ..constants import ANGLE_RESOLUTION_RAD, CART_RESOLUTION_M, FALLEN_ANGLE_RAD

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
    periods_agree : the two period estimates are within 10 % (a regular cycle; an
        irregular one, e.g. encoder-count chatter, gives False)
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
    periods_agree: bool | None = None

    def to_dict(self) -> dict:
        return asdict(self)


def crossing_period(t: np.ndarray, y: np.ndarray) -> float | None:
    """Mean period [s] from crossings of the mean (linear interpolation).

    Upward crossings when there are at least two; otherwise twice the interval between an
    upward and a downward crossing (a slow cycle seen for barely one period); None with
    fewer than two crossings.
    """
    y = y - y.mean()
    up = np.nonzero((y[:-1] < 0) & (y[1:] >= 0))[0]
    idx = up if len(up) >= 2 else np.nonzero((y[:-1] < 0) != (y[1:] < 0))[0]
    if len(idx) < 2:
        return None
    tc = t[idx] - y[idx] * (t[idx + 1] - t[idx]) / (y[idx + 1] - y[idx])
    return float(np.mean(np.diff(tc))) * (1 if len(up) >= 2 else 2)


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


def classify(t, x, theta, resolution=(CART_RESOLUTION_M, ANGLE_RESOLUTION_RAD), fallen_angle: float = FALLEN_ANGLE_RAD,
             ended_fallen: bool = False, window: float = 10.0) -> Oscillation:
    """Classify a run from its samples.

    Settled: over the last ``window`` seconds both signals stay inside a band of
    2 encoder counts (``resolution`` = (cart [m], angle [rad]); a count is taken as at
    least 5e-5, so exact sensors settle inside 0.1 mm and 0.006 deg) about
    their mean.
    The larger of the two signals (in counts) then decides: growing if the second half
    of the window has over 1.25 times the peak-to-peak of the first; settled (still
    converging) if it has under half, or if the window holds under 1.5 periods
    (a creep, not an oscillation); otherwise a limit cycle. Fallen: |theta| reached
    ``fallen_angle``, or the run ended on a safety limit (``ended_fallen``: the pendulum
    fell or the cart hit the track end).
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
    use_theta = thp / band_th >= xp / band_x
    signal = ths if use_theta else xs
    half = len(signal) // 2
    first, second = float(np.ptp(signal[:half])), float(np.ptp(signal[half:]))
    pc, ps = crossing_period(ts, signal), spectral_period(ts, signal)
    window_span = (float(ts[0]), float(ts[-1]))
    if second > 1.25 * first:
        cls = 'growing'
    elif second < 0.5 * first or pc is None or pc > (ts[-1] - ts[0]) / 1.5:
        # decaying, or a creep without 1.5 visible cycles: converging to rest
        return Oscillation('settled', None, xp, thp, None, None, None, stick, window_span)
    else:
        cls = 'limit_cycle'
    onset = _onset(t, theta if use_theta else x, signal)
    agree = bool(pc and ps and abs(pc - ps) <= 0.1 * max(pc, ps))
    return Oscillation(cls, onset, xp, thp, pc, ps, 1.0 / pc if pc else None, stick, window_span, agree)


def _onset(t, y, final) -> float:
    """Time after which ``y`` stays within the range of the ``final`` regime (+20 % margin).

    Growth from rest and decay from a large start both end there.
    """
    lo, hi = float(final.min()), float(final.max())
    margin = 0.2 * (hi - lo)
    out = np.nonzero((y < lo - margin) | (y > hi + margin))[0]
    return float(t[out[-1] + 1]) if len(out) and out[-1] + 1 < len(t) else float(t[0])
