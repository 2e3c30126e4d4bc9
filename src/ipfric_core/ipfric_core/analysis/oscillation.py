"""Oscillation analysis of a sampled run: settled, limit cycle, irregular, growing or fallen.

Works on plain arrays (time [s], cart position [m], angle [rad] from upright), whatever
produced them: the offline closed loop, a bag read back from a ROS run, or a rig's log.
:func:`classify` judges the final regime of a run; :func:`balanced_segments` and
:func:`regimes` cut a long record into the stretches where the pendulum is balanced and,
inside them, into regimes (a limit cycle that holds only for a while, wandering, settling).
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ..constants import ANGLE_RESOLUTION_RAD, CART_RESOLUTION_M, FALLEN_ANGLE_RAD

__all__ = ['CLASSES', 'Oscillation', 'Regime', 'crossing_period', 'classify', 'balanced_segments', 'regimes',
           'regime_of']

CLASSES = ('settled', 'limit_cycle', 'irregular', 'growing', 'fallen')

#: Largest coefficient of variation of the cycle-to-cycle periods of a limit cycle.
PERIOD_SPREAD = 0.25


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
        irregular motion, e.g. encoder-count chatter, gives False)
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
    of the window has over 1.25 times the peak-to-peak of the first (and the motion is
    periodic or under 1.5 cycles; else irregular); settled (still
    converging) if it has under half, or if the window holds under 1.5 periods
    (a creep, not an oscillation); a limit cycle if the motion is periodic (the two
    period estimates within 20 %, the cycle-to-cycle periods within
    :data:`PERIOD_SPREAD`); otherwise irregular (wandering without a period). Fallen:
    |theta| reached ``fallen_angle``, or the run ended on a safety limit
    (``ended_fallen``: the pendulum fell or the cart hit the track end).
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
    cycles = pc is not None and len(_transitions(ts, signal)[0]) >= 3      # 1.5 cycles or more
    period = pc or 0.0
    if second > 1.25 * first:
        cls = 'growing' if not cycles or _regular(ts, signal, period, ps) else 'irregular'
    elif second < 0.5 * first or not cycles:
        # decaying, or a creep without 1.5 visible cycles: converging to rest
        return Oscillation('settled', None, xp, thp, None, None, None, stick, window_span)
    else:
        cls = 'limit_cycle' if _regular(ts, signal, period, ps) else 'irregular'
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


def _transitions(t, y, hysteresis: float = 0.2):
    """Times [s] and directions (+1 up, -1 down) at which ``y`` passes from below its mean
    minus h to above its mean plus h or back (h = ``hysteresis`` times half the
    peak-to-peak): half cycles, counted once despite encoder-count chatter."""
    y = y - y.mean()
    h = hysteresis * 0.5 * float(np.ptp(y))
    level = np.where(y > h, 1, np.where(y < -h, -1, 0))
    idx = np.nonzero(level)[0]
    lv = level[idx]
    change = np.nonzero(lv[1:] != lv[:-1])[0] + 1
    return t[idx[change]], lv[change]


def _regular(t, y, pc: float, ps: float | None) -> bool:
    """A periodic motion: both period estimates within 20 % and the cycle-to-cycle
    periods (between upward transitions) within :data:`PERIOD_SPREAD` of their mean."""
    times, dirs = _transitions(t, y)
    periods = np.diff(times[dirs > 0])
    spread = float(np.std(periods) / np.mean(periods)) if len(periods) >= 2 else 0.0
    return bool(ps and abs(pc - ps) <= 0.2 * max(pc, ps) and spread <= PERIOD_SPREAD)


@dataclass
class Regime:
    """One stretch of a record with one behaviour (times [s], amplitudes [m], [rad]).

    cls : one of CLASSES (never 'fallen': regimes are cut from balanced stretches)
    period_crossings, period_spectrum : s, of the larger signal in encoder counts
    stick_fraction : share of the samples with the cart at rest
    """

    cls: str
    start: float
    end: float
    x_p2p: float
    theta_p2p: float
    period_crossings: float | None
    period_spectrum: float | None
    stick_fraction: float

    def to_dict(self) -> dict:
        return asdict(self)


def balanced_segments(t, theta, max_angle: float = math.radians(20.0), min_duration: float = 2.0,
                      breaks=()) -> list:
    """(first, last + 1) sample indices of the stretches with |theta| < ``max_angle`` [rad]
    (from upright) lasting at least ``min_duration`` [s], none across one of ``breaks`` (indices of
    the samples that follow a gap in the record)."""
    ok = np.abs(np.asarray(theta, float)) < max_angle
    edges = np.diff(np.concatenate([[0], ok.astype(np.int8), [0]]))
    starts, ends = np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]
    out = []
    for a, b in zip(starts, ends):
        cuts = [int(a)] + [int(k) for k in breaks if a < k < b] + [int(b)]
        out += [(p, q) for p, q in zip(cuts, cuts[1:]) if t[q - 1] - t[p] >= min_duration]
    return out


def regimes(t, x, theta, resolution=(4.54e-5, 1.534e-3), window: float = 8.0, step: float = 1.0) -> list:
    """Cut a balanced stretch into :class:`Regime` s.

    Windows of ``window`` s every ``step`` s are classified (:func:`classify`); a window
    differing from both neighbours takes their class; runs of equal class form a regime,
    with boundaries midway between the centres of the windows on either side.
    """
    t, x, theta = (np.asarray(a, float) for a in (t, x, theta))
    window = min(window, float(t[-1] - t[0]))
    starts = np.arange(t[0], t[-1] - window + 1e-9, step) if window > 0 else np.array([t[0]])
    labels = []
    for a in starts:
        m = (t >= a) & (t <= a + window)
        labels.append(classify(t[m], x[m], theta[m], resolution, math.inf, window=window).cls)
    for i in range(1, len(labels) - 1):
        if labels[i - 1] == labels[i + 1] != labels[i]:
            labels[i] = labels[i - 1]
    centres = starts + 0.5 * window
    out, i = [], 0
    while i < len(labels):
        j = i
        while j + 1 < len(labels) and labels[j + 1] == labels[i]:
            j += 1
        a = t[0] if i == 0 else 0.5 * (centres[i - 1] + centres[i])
        b = t[-1] if j == len(labels) - 1 else 0.5 * (centres[j] + centres[j + 1])
        out.append(_regime(t, x, theta, resolution, labels[i], float(a), float(b)))
        i = j + 1
    return out


def regime_of(t, x, theta, a: float, b: float, resolution=(4.54e-5, 1.534e-3),
              fallen_angle: float = FALLEN_ANGLE_RAD, window: float = 8.0) -> Regime:
    """The span [``a``, ``b``] [s] of a run as one regime: the class of its last ``window`` s
    (:func:`classify`), its amplitudes, periods and sticking (e.g. the stretch between two changes
    of the controller's delay)."""
    t, x, theta = (np.asarray(v, float) for v in (t, x, theta))
    m = (t >= a) & (t <= b)
    span = float(t[m][-1] - t[m][0]) if m.sum() > 1 else 0.0
    cls = classify(t[m], x[m], theta[m], resolution, fallen_angle, window=min(window, 0.5 * span) or window).cls
    return _regime(t, x, theta, resolution, cls, a, b)


def _regime(t, x, theta, resolution, cls: str, a: float, b: float) -> Regime:
    m = (t >= a) & (t <= b)
    ts, xs, ths = t[m], x[m], theta[m]
    xp, thp = float(np.ptp(xs)), float(np.ptp(ths))
    band_x, band_th = max(resolution[0], 5e-5), max(resolution[1], 5e-5)
    signal = ths if thp / band_th >= xp / band_x else xs
    steps = np.diff(xs) == 0.0
    periodic = cls in ('limit_cycle', 'irregular', 'growing')
    return Regime(cls, a, b, xp, thp, crossing_period(ts, signal) if periodic else None,
                  spectral_period(ts, signal) if periodic else None, float(steps.mean()) if len(steps) else 0.0)
