"""Simulation error by multiple shooting: the recorded command replayed through the model.

The record is cut into windows. Each window starts from the measured state: encoder
positions, at rest and held by static friction where the encoder stood still around the
start (windows start there whenever they can: that state is known exactly), else with
the angle's rate from a local fit and the cart's rate from the model itself: the rate it reaches
under the recorded commands over the ``LEAD_RATE_S`` before the start (the cart forgets its start
rate within M / (beta + eps); a local fit gives a cart that stops and starts within its span, a
balancing loop chattering at its sample rate, the mean rate of that span, and the model would carry
that error through the window: 23 counts RMS where the true model with the rate from a lead leaves
0.5), then refined to the one (or the rest) that best replays the window's first ``START_FIT_S`` of
readings. With a drive play the motor side's state, which no sensor reads, and the cart's rate are the
model's own over the ``DRIVE_LEAD_S`` before the start (the true drives of 24 cases of the randomised
campaign: 0.5-134 counts left from the state estimated along the measured cart, 0.4-10 from that lead,
against floors of 0.3-8.6); a window without room for that lead starts at the rate that best replays its
first readings, as without a drive. The cart is judged on windows of ``CART_WINDOW_S``; with a
pendulum attached its angle is taken from the measurement there (the upright pendulum is
unstable: a small error in its initial rate would grow into the cart's motion), and the
angle itself is judged on short windows of ``PENDULUM_WINDOW_S`` of the free coupled motion. The model (the
plant of paper eq. (1)-(2), the friction law and the undeclared effects, all evaluated by
:mod:`ipfric_core.physics`: :func:`~ipfric_core.physics.simulate.advance` with
:func:`~ipfric_core.physics.rig.input_effects`, :func:`~ipfric_core.physics.rig.play` and, for a drive
with play, :func:`~ipfric_core.physics.simulate.advance_drive`)
is integrated over the window with each command held until the next time stamp (the
stamps may be uneven). The error is the simulated minus the measured encoder reading, in
encoder counts; samples the record marks invalid (sample overruns) are not compared and
no window spans them.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numba
import numpy as np

from ..analysis.records import Record, smooth_rate
from ..physics.compiled import compiled
from ..physics.plant import drive_contact_depth, motor_force, motor_side_free
from ..physics.rig import drive_means, drive_pieces, input_effects, inputs_through, play
from ..physics.simulate import advance, advance_drive

__all__ = ['every', 'cart_windows', 'angle_windows', 'drive_states', 'applied_commands', 'predict', 'windows_at',
           'quantization_floor', 'reading_errors', 'summary', 'window_sse']

CART_WINDOW_S = 1.0
PENDULUM_WINDOW_S = 0.25
STILL_S = 0.02       # an encoder standing still this long before and after a sample: at rest [s]
FILTER_HZ = 25.0     # corner of the velocity estimate at window starts [Hz]
REST_SPAN = 3.0      # a window reaches this many times its length to end at a rest
#: a window that starts in motion starts at the cart rate that best replays its readings over this long
#: (the local fit's rate smooths a cart that stops and starts within its span) [s]
START_FIT_S = 0.02
#: the start rates tried: the local fit's plus these multiples of the larger of its size and START_COUNTS
#: counts over START_FIT_S (and the vertex of the parabola through the best)
START_RATES = np.array([-1.5, -1.0, -0.6, -0.3, -0.1, 0.0, 0.1, 0.3, 0.6, 1.0, 1.5])
START_COUNTS = 10.0
LEAD_S = 0.1         # no window starts earlier: a delayed command there would come from before the record [s]
#: a window that starts in motion starts at the rate the model reaches over this long before it [s]
LEAD_RATE_S = 0.15
#: a window of a model with a drive play starts at the motor side's state and the cart's rate the model
#: reaches over this long before it: 1.5-8 of the coupled drive's (M + motor-side mass) / (beta + eps),
#: 0.13-0.65 s on the campaign's rigs (a 0.45 s lead left up to 7.6 counts where 1 s left 1.8) [s]
DRIVE_LEAD_S = 1.0


@dataclass(frozen=True)
class Windows:
    """Windows [start, stop) of a record and the measured state at each start."""

    start: np.ndarray     # first sample
    stop: np.ndarray      # one past the last sample
    state: np.ndarray     # (n, 5): x, theta, x', theta', z=0 at the start
    held: np.ndarray      # (n,): 1.0 where the cart stood still at the start
    forced: np.ndarray    # (n_samples, 2) measured angle and rate the simulation follows, or (0, 2)
    motion: np.ndarray    # (n_samples, 2) measured cart speed [m/s] and acceleration [m/s^2] (smooth_rate)

    def __len__(self) -> int:
        return len(self.start)


def local_rate(t: np.ndarray, y: np.ndarray, k: int, valid: np.ndarray, dt: float, half_s: float = 0.01) -> float:
    """dy/dt at sample k [unit/s]: slope of a quadratic fitted over the ``valid`` samples nearest
    to k, as many each side as +/- ``half_s`` holds at the median period ``dt`` [s] (at least two), which
    follows a quantized signal through fast changes. A stale reading repeats an old position at
    a new time: beside a sample overrun it would bend the fit by the motion it missed, so the fit
    reaches past it to the fresh readings on that side."""
    h = max(2, int(round(half_s / dt)))
    idx = np.flatnonzero(valid)
    at = int(np.searchsorted(idx, k))
    use = idx[max(0, at - h):at + h + 1]
    c = np.polyfit(t[use] - t[k], y[use], 2)
    return float(c[1])


def still(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """True at samples whose encoder reading equals every reading within +/- STILL_S."""
    moves = np.concatenate([[0], np.flatnonzero(np.diff(x) != 0.0) + 1, [len(x)]])
    # samples a..b-1 share one reading; inside by STILL_S from both ends (the runs do not overlap)
    lo = np.searchsorted(t, t[moves[:-1]] + STILL_S)
    hi = np.searchsorted(t, t[moves[1:] - 1] - STILL_S, side='right')
    keep = lo < hi
    edge = np.zeros(len(x) + 1, int)
    np.add.at(edge, lo[keep], 1)
    np.add.at(edge, hi[keep], -1)
    return np.cumsum(edge[:-1]) > 0


def make_windows(rec: Record, length_s: float, forced: bool = False, span: float = REST_SPAN) -> Windows:
    """Windows of about ``length_s`` [s] over the valid stretches of ``rec``, from one rest of the
    cart to the next where it can (its state is then known: at rest, held by static friction;
    a window may reach ``span`` times its length for it, a stretch that opens in motion starts
    at its first rest within that reach), else from the measured state with velocities from
    :func:`local_rate` (:func:`windows_at`). With ``forced``, the angle follows
    the measurement in them (its rate: :func:`~ipfric_core.analysis.records.smooth_rate`)."""
    t = rec.t
    valid = usable(rec)
    rest = still(t, rec.x) & valid
    starts, stops = [], []
    edges = np.flatnonzero(np.diff(np.concatenate([[0], valid.astype(int), [0]])))
    for a, b in zip(edges[::2], edges[1::2]):
        # a stretch that opens in motion starts at its first rest within reach (a rate estimated from
        # the encoder's counts carries its rounding into a window that lasts seconds)
        r = np.flatnonzero(rest[a:min(b, int(np.searchsorted(t, t[a] + span * length_s, side='right')))])
        k = a + int(r[0]) if len(r) else a
        while k < b - 1 and t[b - 1] - t[k] >= 0.3 * length_s:
            # rest to rest: with span > 1 the window ends at the first rest after 0.3 of its
            # length (up to span times its length), else at the last rest in its second half;
            # without one, it ends at its length
            end = min(b, int(np.searchsorted(t, t[k] + length_s, side='right')))
            if span > 1.0:
                lo = int(np.searchsorted(t, t[k] + 0.3 * length_s))
                r = np.flatnonzero(rest[lo:min(b, int(np.searchsorted(t, t[k] + span * length_s, side='right')))])
                end = lo + int(r[0]) + 1 if len(r) else end
            else:
                lo = int(np.searchsorted(t, t[k] + 0.5 * length_s))
                r = np.flatnonzero(rest[lo:end])
                end = lo + int(r[-1]) + 1 if len(r) and end < b else end
            end = max(end, k + 2)          # a window holds two samples at least: the loop always advances
            if t[b - 1] - t[end - 1] < 0.3 * length_s:
                end = b                    # a tail too short for a window of its own is the last one's
            starts.append(k)
            stops.append(end)
            k = end - 1
    return windows_at(rec, np.array(starts, int), np.array(stops, int), forced)


def usable(rec: Record) -> np.ndarray:
    """Samples a window may hold: valid, and LEAD_S into the record at the earliest."""
    return rec.valid_mask & (rec.t >= rec.t[0] + LEAD_S)


def windows_at(rec: Record, start: np.ndarray, stop: np.ndarray, forced: bool = False) -> Windows:
    """The windows [start, stop) of ``rec`` with the measured state at each start: at rest where the
    encoder stood still around it (:func:`still`), else with velocities from :func:`local_rate`."""
    t, x = rec.t, rec.x
    th = rec.theta if rec.theta is not None else np.zeros_like(x)
    held = (still(t, x) & usable(rec))[start].astype(float)
    v = np.array([0.0 if h else local_rate(t, x, k, rec.valid_mask, rec.dt) for k, h in zip(start, held)])
    w = (np.array([local_rate(t, th, k, rec.valid_mask, rec.dt) for k in start]) if rec.theta is not None
         else np.zeros(len(start)))
    state = np.column_stack([x[start], th[start], v, w, np.zeros(len(start))])
    angle = (np.column_stack([th, smooth_rate(t, th, rec.valid_mask, FILTER_HZ)]) if forced else np.zeros((0, 2)))
    speed = smooth_rate(t, x, rec.valid_mask, FILTER_HZ)
    return Windows(start, stop, state, held, angle, np.column_stack([speed, np.gradient(speed, t)]))


def every(win: Windows, k: int) -> Windows:
    """Every ``k``-th window of ``win`` (the first, the (k+1)-th, ...)."""
    if k <= 1:
        return win
    pick = np.arange(0, len(win), k)
    return replace(win, start=win.start[pick], stop=win.stop[pick], state=win.state[pick], held=win.held[pick])


def cart_windows(rec: Record) -> Windows:
    """The windows on which the cart is judged: with a pendulum attached, its angle forced and
    the windows stretched up to REST_SPAN times to reach the next rest (a closed loop stops
    seldom and briefly); the cart alone stops often, and its windows keep their length."""
    pendulum = rec.theta is not None
    return make_windows(rec, CART_WINDOW_S, forced=pendulum, span=REST_SPAN if pendulum else 1.0)


def angle_windows(rec: Record) -> Windows:
    """The short windows of free coupled motion on which the angle is judged."""
    return make_windows(rec, PENDULUM_WINDOW_S, span=1.0)


@compiled
def drive_states(pp, dp, t, u, motion):
    """(d, vb, side) of a drive with play at every sample ((d, vb) is the state of
    :func:`~ipfric_core.physics.simulate.advance_drive`; side +1 / -1 in contact pushing forward
    / backward, 0 in the play), estimated by running its motor side along the measured cart: in
    the play as :func:`~ipfric_core.physics.plant.motor_side_free` under the command ``u``
    (after the input effects) while the cart moves as measured (``motion``: speed,
    acceleration); at an edge of the play in contact, moving with the cart, until the contact force
    F = alpha u - beta x' - mass x'' turns against that edge, the contact compressed by that force
    (:func:`~ipfric_core.physics.plant.drive_contact_depth`: a 0.04 mm play against a 22 kN/m contact
    pushing 1 N is compressed by as much as its play). ``dp``: the drive as
    :func:`~ipfric_core.physics.simulate.advance_drive` takes it (play, motor-side mass, stiffness, damping)."""
    n = len(t)
    out = np.empty((n, 3))
    half, mass = 0.5 * dp[0], dp[1]
    d, vb, side = 0.0, motion[0, 0], 0.0
    for k in range(n):
        v0 = motion[k, 0]
        push = motor_force(pp, u[k], v0) - mass * motion[k, 1]
        out[k, 0], out[k, 1], out[k, 2] = drive_contact_depth(dp, side, push) if side != 0.0 else d, vb, side
        if k == n - 1:
            break
        v1 = motion[k + 1, 0]
        if side != 0.0 and side * push >= 0.0:
            vb = v1
            continue
        side = 0.0
        h = t[k + 1] - t[k]
        dx, vb = motor_side_free(pp, mass, vb, u[k], h)
        d += dx - 0.5 * (v0 + v1) * h
        if abs(d) >= half:
            d, vb, side = math.copysign(half, d), v1, math.copysign(1.0, d)
    return out


@compiled
def _sample(pp, fp, ef, deadzone, saturation, drive, first, durations, commands, k, s, mode, dr, substep, forced,
            theta_bias, pendulum):
    """The state after sample interval k, integrated over its pieces of constant applied command (the
    angle set to the measured one where ``forced`` has rows, held at 0 without a pendulum)."""
    for j in range(first[k], first[k + 1]):
        v = input_effects(commands[j], deadzone, saturation)
        if drive[0] > 0.0:
            s, mode, dr = advance_drive(pp, fp, ef, s, mode, dr, v, durations[j], substep, drive)
        else:
            s, mode = advance(pp, fp, ef, s, mode, v, durations[j], substep)
    if len(forced) > 0:
        s = (s[0], forced[k + 1, 0] - theta_bias, s[2], forced[k + 1, 1], s[4])
    elif not pendulum:
        s = (s[0], 0.0, s[2], 0.0, s[4])
    return s, mode, dr


@compiled
def _start_cost(pp, fp, ef, deadzone, saturation, gap, theta_bias, drive, first, durations, commands, k0, k1,
                s, mode, dr, substep, forced, pendulum, xm):
    """Squared error [m^2] of the cart readings over samples k0+1..k1 from the start state ``s``."""
    sq = 0.0
    reading = s[0]
    for k in range(k0, k1):
        s, mode, dr = _sample(pp, fp, ef, deadzone, saturation, drive, first, durations, commands, k, s, mode, dr,
                              substep, forced, theta_bias, pendulum)
        if not math.isfinite(s[0]):
            return math.inf
        reading = play(reading, s[0], gap) if gap > 0.0 else s[0]
        sq += (reading - xm[k + 1]) ** 2
    return sq


@compiled
def _start_rate(pp, fp, ef, deadzone, saturation, gap, theta_bias, drive, first, durations, commands, k0, k1,
                s, mode, dr, substep, forced, pendulum, xm, step):
    """The cart's start rate [m/s] and mode that best replay readings k0+1..k1 (START_FIT_S): the local
    fit's rate ``s[2]`` plus START_RATES times ``step`` [m/s], then the vertex of the parabola through
    the best one and its neighbours where it lowers the error; or at rest, held by static friction (a
    cart that stops and starts again within the local fit's span), where that replays them best."""
    n = len(START_RATES)
    costs = np.empty(n)
    for i in range(n):
        costs[i] = _start_cost(pp, fp, ef, deadzone, saturation, gap, theta_bias, drive, first, durations,
                               commands, k0, k1, (s[0], s[1], s[2] + START_RATES[i] * step, s[3], s[4]), mode,
                               dr, substep, forced, pendulum, xm)
    b = int(np.argmin(costs))
    best, cost = s[2] + START_RATES[b] * step, costs[b]
    if 0 < b < n - 1:
        x0, x1, x2 = START_RATES[b - 1], START_RATES[b], START_RATES[b + 1]
        c0, c1, c2 = costs[b - 1], costs[b], costs[b + 1]
        den = (x1 - x0) * (c1 - c2) - (x1 - x2) * (c1 - c0)
        if den != 0.0:
            x = x1 - 0.5 * ((x1 - x0) ** 2 * (c1 - c2) - (x1 - x2) ** 2 * (c1 - c0)) / den
            v = s[2] + x * step
            c = _start_cost(pp, fp, ef, deadzone, saturation, gap, theta_bias, drive, first, durations, commands,
                            k0, k1, (s[0], s[1], v, s[3], s[4]), mode, dr, substep, forced, pendulum, xm)
            if c < cost:
                best, cost = v, c
    at_rest = (1.0, mode[1], mode[2])
    c = _start_cost(pp, fp, ef, deadzone, saturation, gap, theta_bias, drive, first, durations, commands, k0, k1,
                    (s[0], s[1], 0.0, s[3], s[4]), at_rest, dr, substep, forced, pendulum, xm)
    if c < cost:
        return 0.0, at_rest
    return best, mode


@compiled
def _lead(pp, fp, ef, deadzone, saturation, drive, first, durations, commands, a, k0, s, dr, substep, forced,
          theta_bias, pendulum, xm, speed):
    """The model's cart rate and drive state at sample k0, reached from sample ``a`` under the recorded
    commands, started there at the measured position and smoothed rate ``speed[a]`` with the drive state
    ``dr`` (the angle forced as in :func:`_sample`); returns the start state ``s`` with that rate, and the
    drive state. The cart forgets its start rate within M / (beta + eps), so a lead of a few of those gives
    the rate from the commands rather than from differences of quantized readings (a balancing loop at
    2.1 ms whose cart reverses within the local fit's span: rates 0.074 m/s off, RMS, from the fit, 0.002
    m/s from a 60 ms lead); a drive's motor side, which no sensor reads, forgets its state as the coupled
    drive does, within (M + motor-side mass) / (beta + eps). A lead that diverges returns ``s`` and a drive
    state of NaN (a cart rate or a motor-side rate that is not finite)."""
    ls = (xm[a], forced[a, 0] - theta_bias if len(forced) > 0 else s[1], speed[a],
          forced[a, 1] if len(forced) > 0 else s[3], s[4])
    mode = (0.0, 0.0, 0.0)
    for k in range(a, k0):
        ls, mode, dr = _sample(pp, fp, ef, deadzone, saturation, drive, first, durations, commands, k, ls, mode, dr,
                               substep, forced, theta_bias, pendulum)
        if not (math.isfinite(ls[2]) and math.isfinite(dr[1])):
            return s, (math.nan, math.nan)
    return (s[0], s[1], ls[2], s[3], s[4]), dr


@compiled(parallel=True)   # the windows are independent: one thread each
def _shoot(pp, fp, ef, deadzone, saturation, gap, theta_bias, drive, drives, t, first, durations, commands,
           start, stop, state, held, substep, forced, angle, xm, fit_n, rate_step, lead_n, drive_lead_n, speed, out):
    """Encoder readings (x, theta) predicted in every window, written into ``out`` (n, 2). Each
    sample interval k is integrated over its pieces of constant applied command (``first``,
    ``durations``, ``commands`` of :func:`~ipfric_core.physics.rig.drive_pieces`), each through
    the input effects (:func:`_sample`). Without a pendulum (pp's m = 0) the angle is held at 0; with
    ``forced`` (n, 2) rows, the angle and its rate are set to them (less the bias) after every sample;
    a free angle more than 1.5 rad from the measured one (``angle``) has diverged (the rest of its
    window is NaN). A window that starts in motion starts at the cart rate (or at rest) that best replays
    its first ``fit_n`` readings ``xm`` (:func:`_start_rate`, ``rate_step`` [m/s] its scale), searched
    around the rate the model reaches over the ``lead_n`` samples before from the smoothed rate ``speed``
    there (:func:`_lead`), unless the model has a drive play (``drive`` as
    :func:`~ipfric_core.physics.simulate.advance_drive` takes it, play > 0): then the window's drive state
    and, in motion, the cart's rate are the model's own over the ``drive_lead_n`` samples before, from the
    drive state ``drives`` (n, 3) of :func:`drive_states` there (a window whose angle is free, that has no
    room for such a lead, or whose lead diverged, starts from ``drives`` at its start and, in motion, at the
    rate that best replays its first readings, as a window of a model without a drive does: seed 2027's case
    67, a balancing loop whose estimation part's first window starts 0.11 s in, left 55.9 counts with the
    generator's own drive from the local fit's rate, 8.4 from the fitted one, the other 22 windows 0.3-1))."""
    pendulum = pp[1] > 0.0
    for w in numba.prange(len(start)):
        s = (state[w, 0], state[w, 1] - theta_bias, state[w, 2], state[w, 3], state[w, 4])
        mode = (held[w], 0.0, 0.0)
        k0 = start[w]
        dr = (drives[k0, 0], drives[k0, 1])
        reading = s[0]
        led = False
        if drive[0] > 0.0:
            a = k0 - drive_lead_n
            if a >= 0 and (len(forced) > 0 or not pendulum):
                ls, ldr = _lead(pp, fp, ef, deadzone, saturation, drive, first, durations, commands, a, k0, s,
                                (drives[a, 0], drives[a, 1]), substep, forced, theta_bias, pendulum, xm, speed)
                if math.isfinite(ldr[0]):
                    dr = ldr
                    led = True
                    if held[w] == 0.0:
                        s = ls
        if not led and held[w] == 0.0 and fit_n > 0:
            if lead_n > 0:
                s = _lead(pp, fp, ef, deadzone, saturation, drive, first, durations, commands,
                          max(0, k0 - lead_n), k0, s, dr, substep, forced, theta_bias, pendulum, xm, speed)[0]
            k1 = min(k0 + fit_n, stop[w] - 1)
            v, mode = _start_rate(pp, fp, ef, deadzone, saturation, gap, theta_bias, drive, first, durations,
                                  commands, k0, k1, s, mode, dr, substep, forced, pendulum, xm, rate_step[w])
            s = (s[0], s[1], v, s[3], s[4])
        if w == 0 or stop[w - 1] - 1 != k0:
            # the start; where the window before ends on it, that sample is that window's last
            # prediction (written by another thread: not overwritten here)
            out[k0, 0], out[k0, 1] = reading, s[1] + theta_bias
        for k in range(k0, stop[w] - 1):
            s, mode, dr = _sample(pp, fp, ef, deadzone, saturation, drive, first, durations, commands, k, s, mode,
                                  dr, substep, forced, theta_bias, pendulum)
            if not (math.isfinite(s[0]) and math.isfinite(s[1])) or abs(s[1] + theta_bias - angle[k + 1]) > 1.5:
                for j in range(k + 1, stop[w]):
                    out[j, 0], out[j, 1] = np.nan, np.nan
                break
            reading = play(reading, s[0], gap) if gap > 0.0 else s[0]
            out[k + 1, 0], out[k + 1, 1] = reading, s[1] + theta_bias


def applied_commands(model, rec: Record) -> np.ndarray:
    """The mean command reaching the motor over each sample interval: the record's command through
    the model's delay and lag (:func:`~ipfric_core.physics.rig.drive_means`), deadzone and saturation."""
    tr = model.truth
    u = np.ascontiguousarray(drive_means(rec.t, rec.u, tr.input_delay_s, tr.input_lag_s), float)
    return inputs_through(u, tr.deadzone_V, tr.saturation_V)


@dataclass(frozen=True)
class Prediction:
    """Simulated encoder readings and their error against the measured ones."""

    x: np.ndarray            # simulated cart reading [m]
    theta: np.ndarray | None
    compared: np.ndarray     # samples compared (valid, inside a window, not its first)
    window_of: np.ndarray    # window index of each sample (-1 outside)


_PIECES: dict = {}


def pieces(rec: Record, delay: float, lag: float) -> tuple:
    """:func:`~ipfric_core.physics.rig.drive_pieces` of the record's command, the last few kept (a fit
    replays one record through many models with the same delay and lag)."""
    key = (id(rec.t), id(rec.u), len(rec.t), float(delay), float(lag))
    if key not in _PIECES:
        if len(_PIECES) >= 8:
            _PIECES.pop(next(iter(_PIECES)))
        first, durations, commands = drive_pieces(rec.t, rec.u, delay, lag)
        _PIECES[key] = (first, durations, np.ascontiguousarray(commands, float), rec.t, rec.u)
    return _PIECES[key][:3]


def predict(model, rec: Record, win: Windows) -> Prediction:
    """Replay ``rec``'s command through ``model`` (an :class:`ident.model.ModelVectors`)."""
    tr = model.truth
    first, durations, commands = pieces(rec, tr.input_delay_s, tr.input_lag_s)
    # the free pendulum's windows keep the local fit's rates (its angle would pay for a cart rate fitted alone)
    span = max(3, int(round(START_FIT_S / rec.dt)))
    fit_n = span if len(win.forced) or rec.theta is None else 0
    rate_step = np.maximum(np.abs(win.state[:, 2]), START_COUNTS * rec.x_resolution / (span * rec.dt))
    out = np.full((len(rec.t), 2), np.nan)
    drive = tuple(float(v) for v in tr.drive_vector())
    drives = (drive_states(model.pp, drive, rec.t, applied_commands(model, rec), win.motion)
              if drive[0] > 0.0 else np.zeros((len(rec.t), 3)))
    _shoot(model.pp, model.fp, tr.force_vector(), tr.deadzone_V, tr.saturation_V, tr.backlash_m, tr.bias_theta_rad,
           drive, drives, rec.t, first, durations, commands, win.start, win.stop,
           win.state, win.held, min(1e-3, rec.dt), win.forced,
           rec.theta if rec.theta is not None else np.zeros(len(rec.t)), rec.x, fit_n, rate_step,
           int(round(LEAD_RATE_S / rec.dt)), int(round(DRIVE_LEAD_S / rec.dt)),
           np.ascontiguousarray(win.motion[:, 0]), out)
    window_of = np.full(len(rec.t), -1)
    for i, (a, b) in enumerate(zip(win.start, win.stop)):
        window_of[a + 1:b] = i
    compared = (window_of >= 0) & rec.valid_mask
    return Prediction(out[:, 0], out[:, 1] if rec.theta is not None else None, compared, window_of)


def reading_errors(pred: Prediction, rec: Record, key: str) -> np.ndarray:
    """Simulated minus measured reading of ``key`` ('x' or 'theta') in encoder counts, on the
    compared samples (a diverged simulation counts 1e4 counts, and no error counts more)."""
    c = pred.compared
    sim, meas, res = ((pred.x, rec.x, rec.x_resolution) if key == 'x'
                      else (pred.theta, rec.theta, rec.theta_resolution))
    assert sim is not None and meas is not None, f'no {key} in the record'
    e = (sim[c] - meas[c]) / res
    return np.where(np.isfinite(e), np.clip(e, -1e4, 1e4), 1e4)


def summary(pred: Prediction, rec: Record, win: Windows, key: str) -> dict:
    """RMS error of ``key`` in counts and in percent of the motion within the windows; the motion's own RMS
    [counts] (each reading from its window's first)."""
    c = pred.compared
    e = reading_errors(pred, rec, key)
    meas, res = (rec.x, rec.x_resolution) if key == 'x' else (rec.theta, rec.theta_resolution)
    assert meas is not None, f'no {key} in the record'
    motion = (meas[c] - meas[win.start[pred.window_of[c]]]) / res
    return {f'{key}_windows': len(win), f'{key}_rms_counts': float(np.sqrt(np.mean(e ** 2))),
            f'{key}_percent': float(100 * np.linalg.norm(e) / max(float(np.linalg.norm(motion)), 1.0)),
            f'{key}_motion_counts': float(np.sqrt(np.mean(motion ** 2)))}


def window_sse(pred: Prediction, rec: Record, win: Windows, key: str) -> np.ndarray:
    """Sum of squared errors [counts^2] of each window (the unit of the significance test)."""
    return np.bincount(pred.window_of[pred.compared], reading_errors(pred, rec, key) ** 2, len(win))


#: samples before a window's start that the floor's perfect model is run from, so that its start state is
#: estimated from readings on both sides as the measured one is [s]
FLOOR_LEAD_S = 0.03


def quantization_floor(model, rec: Record, win: Windows, key: str) -> dict:
    """What a perfect model leaves on these windows: the error of ``key`` ('x' or 'theta') in counts when
    the data are ``model``'s own motion, read through the record's encoders, and in % of the measured
    motion (the denominator of :func:`summary`'s percent: a model that hardly moves the cart has a tiny
    motion of its own, and its floor is not a share of that).

    Each window's motion is simulated from the measured state FLOOR_LEAD_S before its start, rounded to
    the encoder's grid (the cart's alone where the angle follows the measurement, both for the free
    angle windows); the window is then shot again from the state estimated from those readings (at rest,
    or velocities from :func:`local_rate`), as the data are shot. The error that leaves is the
    encoders' rounding and what it does to the estimated start states: a model that explains the data
    can do no better. Windows run in two passes (even, odd), so that none overlaps its neighbour."""
    res = rec.x_resolution if key == 'x' else rec.theta_resolution
    lead = max(2, int(np.ceil(FLOOR_LEAD_S / rec.dt)))
    ok = usable(rec)
    first = np.maximum.accumulate(np.where(ok & ~np.concatenate([[False], ok[:-1]]), np.arange(len(ok)), 0))
    forced = len(win.forced) > 0
    sq = motion = 0.0
    n = 0
    for parity in (0, 1):
        pick = np.arange(parity, len(win), 2)
        if not len(pick):
            continue
        start, stop = win.start[pick], win.stop[pick]
        pre = np.maximum(start - lead, first[start])
        truth = predict(model, rec, windows_at(rec, pre, stop, forced))
        synth: dict[str, Any] = {'x': rec.x.copy(), 'theta': None if rec.theta is None else rec.theta.copy()}
        inside = np.zeros(len(rec.t), bool)
        for a, b in zip(pre, stop):
            inside[a:b] = True
        names = ('x',) if forced or rec.theta is None else ('x', 'theta')
        for name in names:
            sim = truth.x if name == 'x' else truth.theta
            assert sim is not None
            meas = synth[name]
            step = rec.x_resolution if name == 'x' else rec.theta_resolution
            origin = float(meas[ok][0])
            grid = np.round((sim - origin) / step) * step + origin
            synth[name] = np.where(inside & np.isfinite(sim), grid, meas)
        srec = replace(rec, x=synth['x'], theta=synth['theta'])
        again = predict(model, srec, windows_at(srec, start, stop, forced))
        c = again.compared & np.isfinite(truth.x)
        got, meas = (again.x, srec.x) if key == 'x' else (again.theta, srec.theta)
        assert got is not None and meas is not None
        e = (got[c] - meas[c]) / res
        c[c] = np.isfinite(e)          # a diverged replay's samples count neither as error nor as motion
        e = e[np.isfinite(e)]
        sq += float(e @ e)
        n += len(e)
        measured = rec.x if key == 'x' else rec.theta      # the motion of the data, as :func:`summary`'s
        assert measured is not None
        motion += float(np.sum(((measured[c] - measured[start[again.window_of[c]]]) / res) ** 2))
    rms = float(np.sqrt(sq / max(n, 1)))
    return {f'{key}_floor_counts': rms, f'{key}_floor_percent': float(100 * np.sqrt(sq) / max(np.sqrt(motion), 1.0))}
