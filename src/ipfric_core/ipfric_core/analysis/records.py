"""Measured data for identification: one record type and its loaders.

A :class:`Record` is a sampled experiment on a prismatic axis: time t [s], position
x [m], the input u in its own unit (V) with the factor ``gain`` that turns it into a
force [N/unit], and, when a pendulum is attached, its angle theta [rad from upright].
Loaders: a run bag of ``./ipfric run`` (measured topics only: encoders and commands),
a CSV table (plain or gzip), the EMPS benchmark files (force ``gtau * vir``, position ``qm``).
Bad input is refused with a :class:`ConfigError` naming the problem, the row and the column.

Data as rigs write them are taken as they are and their defects named in ``Record.notes``:
uneven time stamps (each command is held until the next stamp), sample overruns (a stamp
that jumps, then encoders frozen: those readings are marked invalid), an angle that wraps
at +/-pi (unwrapped) or is measured from hanging (pi at upright: mapped to upright).
"""
from __future__ import annotations

import codecs
import csv
import gzip
import math
from array import array
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path
from typing import IO

import numpy as np
from scipy.signal import butter, sosfiltfilt

from ..physics.params import ConfigError, PlantParams

__all__ = ['Record', 'smallest_step', 'uneven', 'filtered_on_grid', 'smooth_rate', 'angle_equation', 'upright_angle',
           'frozen_tail', 'gap_starts',
           'ANGLE_ZEROS', 'is_log', 'parse_columns', 'load', 'trajectory_record']

MIN_SAMPLES = 200
#: stamps whose longest period is more than this many times their shortest are uneven
UNEVEN_RATIO = 1.5
MIN_PART_COUNTS = 100   # encoder counts an estimation or validation part must move at least
MAX_ROWS = 2_000_000    # a longer CSV is refused (33 min at 1 kHz; identification would take hours)
MAX_VOLTAGE = 100.0     # |u| beyond this is not a drive command [V] (lab drives give 5-48 V)
MAX_CART_SPEED = 10.0   # a position step faster than this between two rows is a corrupt row [m/s]
MAX_ANGLE_RATE = 100.0  # a row whose angle leaves and comes back faster than this (unwrapped) is corrupt [rad/s]
MIN_PERIOD_S = 1e-4     # shortest median sample period taken as seconds (10 kHz) [s]
MAX_PERIOD_S = 0.1      # longest [s]
OVERRUN_JUMP = 1.75     # a stamp step this many times the median period starts an overrun
GAP_PERIODS = 20        # a stamp step this many median periods (and at least GAP_S) is a gap in the log
GAP_S = 0.05            # [s]
FROZEN_S = 0.5          # a tail this long where no column changes is a stopped log [s]
RATE_HZ = 25.0          # corner of the filtered derivatives of a record [Hz]
MAX_FROZEN = 5          # samples after a jump that may repeat the last reading


@dataclass(frozen=True)
class Record:
    """One experiment (SI units).

    gain : N per unit of u (alpha [N/V] for the rig, gtau for EMPS)
    back_emf : known velocity damping of the drive [N s/m] (beta of eq. 2; 0 if unknown)
    pendulum : (m [kg], l [m], g [m/s^2]) when theta is measured, else None
    normal_force : F_N [N] used to express friction as coefficients mu
    stick_velocity : |x'| [m/s] below which a sample counts as stuck (left out of the fit)
    valid : False where a reading is stale (a sample overrun); None = all valid
    notes : what loading found and did (overruns, resampling, angle mapping)
    plant : the plant constants the record was read with (None for a force-input record)
    """

    name: str
    t: np.ndarray
    x: np.ndarray
    u: np.ndarray
    gain: float
    back_emf: float = 0.0
    theta: np.ndarray | None = None
    pendulum: tuple | None = None
    normal_force: float = 1.0
    stick_velocity: float = 0.0
    cutoff_hz: float = 20.0
    valid: np.ndarray | None = None
    notes: tuple = field(default=())
    plant: PlantParams | None = None

    @cached_property
    def dt(self) -> float:
        """The median sample period [s] (kept: the simulation error reads it at every prediction)."""
        return float(np.median(np.diff(self.t)))

    @property
    def valid_mask(self) -> np.ndarray:
        return np.ones(len(self.t), bool) if self.valid is None else self.valid

    @cached_property
    def x_resolution(self) -> float:
        """The cart encoder's count [m]: the smallest step of x."""
        return smallest_step(self.x)

    @cached_property
    def theta_resolution(self) -> float:
        """The angle encoder's count [rad]: the smallest step of theta."""
        return smallest_step(self.theta) if self.theta is not None else 1.0

    def part(self, a: int, b: int, tag: str) -> Record:
        """Samples a .. b - 1 as a record of their own, ``tag`` added to its name."""
        return replace(self, name=f'{self.name} ({tag})', t=self.t[a:b], x=self.x[a:b], u=self.u[a:b],
                       theta=None if self.theta is None else self.theta[a:b],
                       valid=None if self.valid is None else self.valid[a:b])

    def motion(self) -> np.ndarray:
        """Encoder counts moved up to each sample (cart and angle together): where the record moves."""
        steps = np.abs(np.diff(self.x)) / self.x_resolution
        if self.theta is not None:
            steps = steps + np.abs(np.diff(self.theta)) / self.theta_resolution
        return np.concatenate([[0.0], np.cumsum(np.where(self.valid_mask[1:], steps, 0.0))])

    def split(self, fraction: float) -> tuple[Record, Record]:
        """(estimation, validation): the first part holds ``fraction`` of the record's motion
        (:meth:`motion`), the rest the remainder, so both parts move whatever the record does
        (a log that moves early and then rests is not split in time). ConfigError when the record
        hardly moves or a part would hold fewer than MIN_PART_COUNTS of motion."""
        moved = self.motion()
        total = float(moved[-1])
        k = int(np.searchsorted(moved, fraction * total))
        k = min(max(k, MIN_SAMPLES // 2), len(self.t) - MIN_SAMPLES // 2)
        part_motion = (float(moved[k]), total - float(moved[k]))
        if min(part_motion) < MIN_PART_COUNTS:
            raise ConfigError(f'{self.name}: cannot split into estimation and validation parts that both move: '
                              f'{total:.0f} encoder counts of motion in all, {part_motion[0]:.0f} before and '
                              f'{part_motion[1]:.0f} after t = {self.t[k]:.3g} s (each part needs '
                              f'{MIN_PART_COUNTS:g}); record more motion, or give --validation FILE')
        return self.part(0, k, 'estimation'), self.part(k, len(self.t), 'validation')


def smallest_step(y, still: float = 1.0) -> float:
    """The smallest nonzero step of a sampled signal: its encoder's count when it is quantized
    (steps below 1e-12 of its size are rounding); ``still`` if it never moves."""
    y = np.asarray(y, float)
    steps = np.abs(np.diff(y))
    steps = steps[steps > 1e-12 * max(1.0, float(np.max(np.abs(y))))] if len(y) else steps
    return float(steps.min()) if len(steps) else still


def uneven(t: np.ndarray) -> bool:
    """True where the periods between the stamps ``t`` [s] range over more than UNEVEN_RATIO (jitter, overruns)."""
    d = np.diff(t)
    return bool(np.max(d) > UNEVEN_RATIO * np.min(d) + 1e-9)


def filtered_on_grid(t: np.ndarray, y: np.ndarray, sos: np.ndarray, valid: np.ndarray | None = None,
                     derivatives: int = 0) -> list[np.ndarray]:
    """``y`` through the zero-phase filter ``sos`` (designed at the median period of the stamps ``t`` [s]) on a
    uniform grid of that period, the ``valid`` samples read off linearly, and its first ``derivatives`` time
    derivatives [unit/s^k], each read back at ``t``."""
    valid = np.ones(len(t), bool) if valid is None else valid
    dt = float(np.median(np.diff(t)))
    grid = np.arange(t[0], t[-1] + 0.5 * dt, dt)
    out = [sosfiltfilt(sos, np.interp(grid, t[valid], y[valid]))]
    for _ in range(derivatives):
        out.append(np.gradient(out[-1], dt))
    return [np.interp(t, grid, s) for s in out]


def smooth_rate(t: np.ndarray, y: np.ndarray, valid: np.ndarray | None = None,
                cutoff_hz: float = RATE_HZ) -> np.ndarray:
    """dy/dt of a sampled signal [unit/s]: zero-phase 4th-order Butterworth at ``cutoff_hz`` on a uniform
    grid (:func:`filtered_on_grid`: the record's median period; ``valid`` samples only)."""
    dt = float(np.median(np.diff(t)))
    return filtered_on_grid(t, y, butter(4, min(cutoff_hz, 0.4 / dt), fs=1.0 / dt, output='sos'), valid, 1)[1]


def overruns(t: np.ndarray, readings: list) -> np.ndarray:
    """False at stale readings: after a stamp that jumps by more than OVERRUN_JUMP median
    periods, the samples that repeat its reading (every encoder frozen), at most MAX_FROZEN of
    them. A real-time loop that overran wrote them."""
    dt = np.diff(t)
    valid = np.ones(len(t), bool)
    for j in np.flatnonzero(dt > OVERRUN_JUMP * np.median(dt)) + 1:
        k = j + 1
        while k < len(t) and k - j <= MAX_FROZEN and all(r[k] == r[j] for r in readings):
            valid[k] = False
            k += 1
    return valid


ANGLE_ZEROS = ('auto', 'upright', 'hanging')
#: the t statistic a term of the pendulum's equation needs to decide an angle column's zero or sign
CONVENTION_T = 6.0
#: the record names a CSV's columns map to (``--columns NAME=HEADER``)
COLUMNS = ('t', 'x', 'voltage', 'theta')
#: suffixes of rig logs (a CSV table, a MATLAB file); anything else is a run bag
LOG_SUFFIXES = ('.csv', '.mat')


def is_log(path: str | Path) -> bool:
    """True for a rig log (:data:`LOG_SUFFIXES`, a gzipped CSV too), False for a bag or run directory."""
    name = Path(path).name.lower()
    return Path(name).suffix in LOG_SUFFIXES or name.endswith('.csv.gz')


def parse_columns(text: str | None) -> dict[str, str]:
    """``t=time_s,x=cart_m,...`` as name -> CSV header (names of :data:`COLUMNS`)."""
    columns = {}
    for item in text.split(',') if text else []:
        key, _, name = item.partition('=')
        if not name or key.strip() not in COLUMNS:
            raise ConfigError(f'--columns: {item!r} is not NAME=HEADER with NAME one of {", ".join(COLUMNS)}')
        columns[key.strip()] = name.strip()
    return columns


def angle_equation(t, x, theta) -> tuple[np.ndarray, np.ndarray]:
    """The pendulum's own equation (paper eq. 1), theta'' = a sin(theta) + b x'' cos(theta), fitted to
    the filtered record by least squares (every 10 ms, the first and last 0.1 s left out): (a, b) and
    their t statistics. For theta from upright with the paper's sign, a = 3 g / (4 l) > 0 and
    b = -3 / (4 l) < 0; measured from hanging, both change sign; positive the other way round, b does."""
    acc = smooth_rate(t, smooth_rate(t, x))
    wdd = smooth_rate(t, smooth_rate(t, theta))
    inside = np.flatnonzero((t > t[0] + 0.1) & (t < t[-1] - 0.1))
    idx = inside[::max(1, int(round(0.01 / float(np.median(np.diff(t))))))]
    A = np.column_stack([np.sin(theta[idx]), acc[idx] * np.cos(theta[idx])])
    y = wdd[idx]
    if len(idx) < 10 or np.linalg.matrix_rank(A) < 2:
        return np.zeros(2), np.zeros(2)
    coef = np.linalg.lstsq(A, y, rcond=None)[0]
    r = y - A @ coef
    cov = float(r @ r) / max(1, len(y) - 2) * np.linalg.pinv(A.T @ A)
    return coef, coef / np.sqrt(np.maximum(np.diag(cov), 1e-300))


def sized(coef: float, tstat: float, expected: float) -> bool:
    """A term of the pendulum's equation shows: significant (t >= CONVENTION_T) and of the size the
    declared pendulum gives it (0.6-1.6 times ``expected``)."""
    return abs(tstat) >= CONVENTION_T and 0.6 < abs(coef) / expected < 1.6


def misread(t, x, theta, l: float, g: float, equation: tuple) -> None:
    """Refuse a record whose columns parse but cannot be right, by the pendulum's own equation
    (``equation``: :func:`angle_equation` of the columns as read): theta in degrees (the gravity term
    of the declared pendulum's size, the coupling to the cart 57.3 times its size), or x and theta
    swapped (read the other way round, both terms of the declared pendulum's size, and not so as they
    are). Both terms must agree: in a balancing loop the controller ties the cart to the angle, and
    one term alone can take the size the other leaves."""
    (grav, coupling), (t_grav, t_coupling) = equation
    if sized(grav, t_grav, 0.75 * g / l) and sized(coupling, t_coupling, 0.75 / l * math.degrees(1.0)):
        raise ConfigError(f'columns: theta looks like degrees, not radians: the pendulum\'s coupling to the '
                          f'cart is {abs(coupling):.3g} per unit (t = {abs(t_coupling):.3g}) where the declared '
                          f'pendulum gives {0.75 / l:.3g} per rad; allowed: theta in rad')
    if sized(grav, t_grav, 0.75 * g / l) or sized(coupling, t_coupling, 0.75 / l):
        return
    (grav, coupling), (t_grav, t_coupling) = angle_equation(t, theta, x)
    if sized(grav, t_grav, 0.75 * g / l) and sized(coupling, t_coupling, 0.75 / l):
        raise ConfigError(f'columns: x and theta look swapped: the pendulum\'s equation shows its gravity term '
                          f'(t = {abs(t_grav):.3g}, {abs(grav):.3g} 1/s^2 where the declared pendulum gives '
                          f'{0.75 * g / l:.3g}) and its coupling to the cart ({abs(coupling):.3g} per m, '
                          f'{0.75 / l:.3g} declared) only when they are read the other way round; allowed: x in m, '
                          f'theta in rad (--columns maps them)')


def upright_angle(t, x, theta, l: float, g: float, zero: str = 'auto') -> tuple[np.ndarray, list[str]]:
    """The angle column as the model takes it: radians from upright, the paper's sign, unwrapped
    (a hanging pendulum about pi). ``zero`` says where the column is zero: 'upright', 'hanging' (then
    pi is added), or 'auto': the pendulum's own equation decides (:func:`angle_equation`: the sign of
    its gravity term tells upright from hanging, that of its coupling to the cart the angle's sign,
    each when its t statistic reaches CONVENTION_T and its size is the declared pendulum's); without
    that evidence, from hanging when the angle stays more than 90 deg from its zero (a balancing
    rig's log spends its time upright), else from upright, and the paper's sign."""
    if zero not in ANGLE_ZEROS:
        raise ConfigError(f'angle zero {zero!r} is not one of {", ".join(ANGLE_ZEROS)}')
    notes = []
    th = np.unwrap(theta)
    if np.any(np.abs(np.diff(theta)) > np.pi):
        notes.append('angle wrapped at +/-pi: unwrapped')
    equation = angle_equation(t, x, th)
    (grav, coupling), (t_grav, t_coupling) = equation
    # the raw column's coefficients are (c a, s c b) for the reading s * column + (pi if c < 0): a > 0, b < 0;
    # a term decides when it is significant and of the size the declared pendulum gives it (0.6-1.6x)
    shows_gravity = sized(grav, t_grav, 0.75 * g / l)
    shows_coupling = sized(coupling, t_coupling, 0.75 / l)
    if zero == 'auto':
        misread(t, x, th, l, g, equation)
    turns = np.round(np.median(th) / (2 * np.pi))
    far = np.median(np.abs(th - 2 * np.pi * turns)) > np.pi / 2
    if zero == 'auto' and shows_gravity:
        offset = np.pi if grav < 0 else 0.0
        notes.append('angle read as measured ' + ('from hanging' if offset else 'from upright') + ' (its equation\'s '
                     f'gravity term, t = {abs(t_grav):.3g})')
    elif zero == 'auto':
        # no evidence from the motion: a log spends its time where its rig balances it, upright
        offset = np.pi if far else 0.0
        notes.append('the pendulum\'s motion does not show where its angle is zero (the gravity term of its '
                     f'equation is {grav:.3g} 1/s^2 with t = {t_grav:.2g}, {0.75 * g / l:.3g} expected): read as '
                     + ('measured from hanging, as the angle stays more than 90 deg from its zero' if far else
                        'measured from upright') + ', in radians as written (nor can degrees or x and theta '
                     'swapped be told from it); --angle-zero says otherwise')
    else:
        offset = np.pi if zero == 'hanging' else 0.0
    flip = -1.0 if offset else 1.0
    sign = -flip * float(np.sign(coupling)) if shows_coupling else 1.0
    if sign < 0:
        notes.append(f'the angle is positive the other way round from the paper\'s (its coupling to the cart, '
                     f't = {abs(t_coupling):.3g}): its sign is changed')
    if abs(t_coupling) >= CONVENTION_T:
        l_data = 0.75 / abs(coupling)
        if not 0.7 < l_data / l < 1.4 and shows_coupling:
            notes.append(f'the pendulum\'s coupling to the cart says l = {l_data:.3g} m, the declared l is {l:.3g} m')
    out = sign * th + offset
    turns = np.round(np.median(out) / (2 * np.pi))
    if turns:
        out = out - 2 * np.pi * turns
    hang = np.abs(np.angle(np.exp(1j * out))) > np.pi / 2
    if hang.mean() > 0.5:
        notes.append(f'the pendulum hangs ({100 * hang.mean():.0f} % of the samples more than 90 deg from upright)')
    elif hang.any():
        notes.append(f'the pendulum passes between hanging and upright ({100 * hang.mean():.0f} % of the samples '
                     f'hanging)')
    return out, notes


def gap_starts(t: np.ndarray) -> np.ndarray:
    """Indices of the samples that follow a gap in a log: a stamp step of GAP_PERIODS median periods
    and at least GAP_S [s]."""
    d = np.diff(t)
    return np.flatnonzero(d > max(GAP_PERIODS * float(np.median(d)), GAP_S)) + 1


def check_record(rec: Record, angle_zero: str = 'auto') -> Record:
    """Refuse what cannot be measured data (NaN, time going back, absurd ranges, too few
    samples); take what rigs write (uneven stamps, overruns, wrapped or hanging angles)."""
    n = len(rec.t)
    arrays = {'t': rec.t, 'x': rec.x, 'voltage': rec.u}
    if rec.theta is not None:
        arrays['theta'] = rec.theta
    for k, a in arrays.items():
        if len(a) != n:
            raise ConfigError(f'{rec.name}: column {k} has {len(a)} samples, t has {n}')
        bad = np.nonzero(~np.isfinite(a))[0]
        if len(bad):
            raise ConfigError(f'{rec.name}: column {k} is NaN or infinite at row {bad[0] + 1} '
                              f'({len(bad)} such rows); clean or cut the data')
    if n < MIN_SAMPLES:
        raise ConfigError(f'{rec.name}: {n} samples is too short; at least {MIN_SAMPLES} are needed')
    d = np.diff(rec.t)
    if np.any(d <= 0):
        i = int(np.nonzero(d <= 0)[0][0])
        raise ConfigError(f'{rec.name}: time is not increasing at row {i + 2} '
                          f'(t = {rec.t[i]:g} then {rec.t[i + 1]:g} s)')
    period = float(np.median(d))
    if not MIN_PERIOD_S <= period <= MAX_PERIOD_S:
        guess = ('minutes' if MIN_PERIOD_S <= 60 * period <= MAX_PERIOD_S else
                 'ms' if MIN_PERIOD_S <= period / 1e3 <= MAX_PERIOD_S else
                 'us or ns' if period > MAX_PERIOD_S else 'another unit')
        raise ConfigError(f'{rec.name}: column t has a median sample period of {period:g}; allowed: seconds '
                          f'between {MIN_PERIOD_S:g} and {MAX_PERIOD_S:g} (rigs sample at 10 Hz to 10 kHz); '
                          f'is t in {guess}?')
    if np.ptp(rec.x) > 20.0:
        raise ConfigError(f'{rec.name}: column x spans {np.ptp(rec.x):g}; expected metres (a prismatic axis '
                          f'moves less than 20 m); is it in mm or counts?')
    if np.ptp(rec.x) == 0.0:
        raise ConfigError(f'{rec.name}: column x never changes; nothing moved')
    speed = np.abs(np.diff(rec.x)) / d
    if np.any(speed > MAX_CART_SPEED):
        i = int(np.flatnonzero(speed > MAX_CART_SPEED)[0])
        raise ConfigError(f'{rec.name}: column x jumps from {rec.x[i]:g} to {rec.x[i + 1]:g} m at row {i + 2} '
                          f'(t = {rec.t[i + 1]:g} s), {speed[i]:.3g} m/s; allowed at most {MAX_CART_SPEED:g} m/s '
                          f'between rows (a corrupt row, or x not in metres?); clean or cut the data')
    big = np.flatnonzero(np.abs(rec.u) > MAX_VOLTAGE)
    if len(big):
        raise ConfigError(f'{rec.name}: column voltage is {rec.u[big[0]]:g} at row {big[0] + 1}; allowed '
                          f'|voltage| <= {MAX_VOLTAGE:g} V (a drive command; is it a corrupt row, or in mV?)')
    if not np.any(rec.u):
        raise ConfigError(f'{rec.name}: column voltage is 0 throughout; nothing drove the axis')
    notes = list(rec.notes)
    theta = rec.theta
    if theta is not None:
        wrapped = np.abs(np.angle(np.exp(1j * theta)))
        off_axis = np.median(np.minimum(wrapped, np.pi - wrapped))   # from upright or hanging [rad]
        if np.max(np.abs(theta)) > 2 * np.pi and off_axis > 0.5:
            raise ConfigError(f'{rec.name}: column theta reaches {np.max(np.abs(theta)):g}; expected radians '
                              f'from upright or from hanging (degrees?)')
        _, length, gravity = rec.pendulum if rec.pendulum is not None else (0.0, 1.0, 9.81)
        rate = np.diff(np.unwrap(theta)) / d
        spikes = np.flatnonzero((np.abs(rate[:-1]) > MAX_ANGLE_RATE) & (np.abs(rate[1:]) > MAX_ANGLE_RATE)
                                & (rate[:-1] * rate[1:] < 0))
        if len(spikes):
            i = int(spikes[0])
            raise ConfigError(f'{rec.name}: column theta jumps from {theta[i]:g} to {theta[i + 1]:g} rad at row '
                              f'{i + 2} (t = {rec.t[i + 1]:g} s) and back, {abs(rate[i]):.3g} rad/s unwrapped; '
                              f'allowed at most {MAX_ANGLE_RATE:g} rad/s between rows (a corrupt row?); clean or '
                              f'cut the data')
        theta, found = upright_angle(rec.t, rec.x, theta, length, gravity, angle_zero)
        notes += found
    valid = overruns(rec.t, [rec.x] + ([theta] if theta is not None else []))
    gaps = gap_starts(rec.t)
    if len(gaps):
        valid[gaps] = False
        notes.append(f'{len(gaps)} gap(s) in the log (longest {float(np.max(d[gaps - 1])):.3g} s, first at '
                     f't = {rec.t[gaps[0] - 1]:.3g} s): nothing is compared or analysed across one')
    if not valid.all():
        notes.append(f'{int((~valid).sum())} stale readings after {int(np.sum(np.diff(valid.astype(int)) == -1))} '
                     f'sample overruns (stamp jump, encoders frozen): not compared')
    if uneven(rec.t):
        notes.append(f'uneven stamps (period {np.min(d):g} to {np.max(d):g} s, median {period:g} s): '
                     f'each command held until the next stamp')
    return replace(rec, theta=theta, valid=valid, notes=tuple(notes))


def _rig_record(name, t, x, u, theta, plant: PlantParams, angle_zero: str = 'auto', notes=()) -> Record:
    t, x, u = (np.asarray(a, float) for a in (t, x, u))
    theta = None if theta is None else np.asarray(theta, float)
    end, stopped = frozen_tail(t, [x, u] + ([theta] if theta is not None else []))
    if stopped:
        notes = tuple(notes) + (stopped,)
        t, x, u, theta = t[:end], x[:end], u[:end], None if theta is None else theta[:end]
    pend = None if theta is None else (plant.m, plant.l, plant.g)
    fn = plant.normal_force if theta is not None else plant.M * plant.g
    rec = check_record(Record(name, t, x, u, plant.alpha, plant.beta, theta, pend, fn, stick_velocity=2e-3,
                              cutoff_hz=25.0, plant=plant), angle_zero)
    return replace(rec, notes=tuple(notes) + rec.notes)


def frozen_tail(t: np.ndarray, columns: list) -> tuple[int, str]:
    """(samples to keep, note): a log whose columns all stop changing FROZEN_S or more before its end (a
    rig stopped at the track's end, a logger left running) is cut after the last change; (len, '') else."""
    n = len(t)
    changed = np.zeros(max(n - 1, 0), bool)
    for c in columns:
        changed |= np.diff(c) != 0.0
    moves = np.flatnonzero(changed)
    last = int(moves[-1]) + 2 if len(moves) else n
    if last < n and t[-1] - t[last - 1] >= FROZEN_S and last >= MIN_SAMPLES:
        return last, (f'nothing changes after t = {t[last - 1]:.3g} s (the last {t[-1] - t[last - 1]:.3g} s, '
                      f'{n - last} samples): the stopped tail is left out')
    return n, ''


def pendulum_angle(theta, cart_alone: bool) -> tuple[np.ndarray | None, list[str]]:
    """The angle column of a record as the pendulum gives it: None with ``cart_alone``, or when the
    column holds one value throughout (a rig logs a constant, often 0, with its pendulum removed)."""
    if theta is None or cart_alone:
        return None, ['pendulum off (--cart-alone): its angle is not read'] if theta is not None else []
    theta = np.asarray(theta, float)
    if len(theta) and np.all(theta == theta[0]):
        return None, [f'the angle column is {theta[0]:g} throughout: the pendulum is off (cart alone)']
    return theta, []


def _text_lines(path: Path):
    """The lines of a text file (gzip when it ends in .gz), a byte-order mark dropped."""
    try:
        raw: IO[bytes] = path.open('rb')
    except OSError as exc:
        raise ConfigError(f'{path}: cannot read ({exc.strerror})') from exc
    data: IO[bytes] | gzip.GzipFile = gzip.GzipFile(fileobj=raw) if path.suffix.lower() == '.gz' else raw
    try:
        for lineno, line in enumerate(data, 1):   # decoded line by line: an error names its line and column
            if lineno == 1 and line.startswith(codecs.BOM_UTF8):
                line = line[len(codecs.BOM_UTF8):]
            try:
                text = line.decode('utf-8')
            except UnicodeDecodeError as exc:
                raise ConfigError(f'{path}: line {lineno}, byte column {exc.start + 1}: byte '
                                  f'{line[exc.start]:#04x} is not UTF-8 ({exc.reason}); not a text (UTF-8) CSV '
                                  f'file: save it as UTF-8') from None
            yield lineno, text
    except (OSError, EOFError) as exc:
        raise ConfigError(f'{path}: cannot read ({exc})') from exc
    finally:
        data.close()
        raw.close()


def load_csv(path: str | Path, plant: PlantParams, columns: dict | None = None, angle_zero: str = 'auto',
             cart_alone: bool = False) -> Record:
    """CSV (or .csv.gz) with a header: t [s], x [m], voltage [V] and optionally theta [rad].

    ``columns`` maps these names to the file's headers, e.g. {'x': 'cart_m'}. Lines that
    start with '#' are comments. Read as a stream into typed arrays (memory about 8 bytes
    a value); at most MAX_ROWS rows. The angle is read as :func:`pendulum_angle` says.
    """
    path = Path(path)
    cols = {n: n for n in COLUMNS}
    unknown = set(columns or {}) - set(cols)
    if unknown:
        raise ConfigError(f'column mapping: unknown name(s) {", ".join(sorted(unknown))}; '
                          f'allowed: {", ".join(COLUMNS)}')
    cols.update(columns or {})
    lines = ((i, ln) for i, ln in _text_lines(path) if ln.strip() and not ln.lstrip().startswith('#'))
    head = [ln for _, ln in zip(range(100), _text_lines(path))]
    if path.suffix.lower() != '.gz' and head:
        estimate = path.stat().st_size / (sum(len(ln[1]) for ln in head) / len(head))
        if estimate > 1.5 * MAX_ROWS:
            raise ConfigError(f'{path}: about {estimate:.3g} rows ({path.stat().st_size / 1e6:.0f} MB); at most '
                              f'{MAX_ROWS} are read: cut or decimate the log')
    first = next(lines, None)
    if first is None:
        raise ConfigError(f'{path}: empty file; expected a header t,x,voltage[,theta]')
    header = [h.strip() for h in next(csv.reader([first[1]]))]
    for need in ('t', 'x', 'voltage'):
        if cols[need] not in header:
            raise ConfigError(f'{path}: missing column {cols[need]!r} ({need}); header has '
                              f'{", ".join(header)}; map columns with --columns {need}=NAME')
    names = [n for n in ('t', 'x', 'voltage', 'theta') if cols[n] in header]
    where = [header.index(cols[n]) for n in names]
    data = {n: array('d') for n in names}
    rows = 0
    for lineno, line in lines:
        fields = next(csv.reader([line]))
        if len(fields) != len(header):
            raise ConfigError(f'{path}: row {lineno} has {len(fields)} fields, the header has {len(header)} '
                              f'({", ".join(header)})')
        for n, j in zip(names, where):
            try:
                if '_' in fields[j]:   # float() reads 1_0.5 as 10.5
                    raise ValueError
                data[n].append(float(fields[j]))
            except ValueError:
                raise ConfigError(f'{path}: row {lineno}, column {cols[n]!r}: {fields[j].strip()!r} is not a '
                                  f'number') from None
        rows += 1
        if rows > MAX_ROWS:
            raise ConfigError(f'{path}: more than {MAX_ROWS} rows; cut or decimate the log (at most {MAX_ROWS})')
    if rows == 0:
        raise ConfigError(f'{path}: a header and no data rows; expected rows of {", ".join(header)}')
    arrays = {n: np.frombuffer(data[n], float) for n in names}
    theta, notes = pendulum_angle(arrays.get('theta'), cart_alone)
    return _rig_record(path.name, arrays['t'], arrays['x'], arrays['voltage'], theta, plant, angle_zero, notes)


def load_bag(path: str | Path, plant: PlantParams | None = None, cart_alone: bool = False) -> Record:
    """A run of ``./ipfric run``: encoders (joint_states) and commands (voltage_command) only.

    The command of sample k has the stamp of the measurement it answers and is held over
    [t_k, t_k+1). The plant constants come from ``plant`` or else the run's stored
    scenario (the design side: alpha, beta, masses; never the friction or the truth).
    """
    from .bagread import read_run
    run = read_run(path)
    if plant is None:
        if run.truncated and not run.config:
            raise ConfigError(f'{path}: the bag is truncated ({run.truncation_detail}): its scenario, stored at the '
                              f'end of the file with the summary, is cut off, so the plant constants are missing; '
                              f'give them with --plant')
        if not run.config or 'plant' not in run.config:
            raise ConfigError(f'{path}: the bag stores no scenario (no plant section); give the plant constants '
                              f'with --plant')
        plant = PlantParams.from_dict(run.config['plant'], 'bag scenario plant')
    k = np.searchsorted(run.t, run.command_t)
    ok = (k < len(run.t)) & (np.abs(run.t[np.minimum(k, len(run.t) - 1)] - run.command_t) < 1e-6)
    if ok.sum() < MIN_SAMPLES:
        raise ConfigError(f'{path}: only {int(ok.sum())} commands match an encoder sample; '
                          f'at least {MIN_SAMPLES} are needed')
    idx = k[ok]
    theta, notes = pendulum_angle(run.theta[idx], cart_alone)
    return _rig_record(Path(path).name, run.t[idx], run.x[idx], run.voltage[ok], theta, plant, notes=notes)


def load_emps(path: str | Path) -> Record:
    """EMPS benchmark .mat: force input gtau * vir [N], motor position on the load side qm [m]."""
    from scipy.io import loadmat
    try:
        d = loadmat(str(path))
    except Exception as exc:  # scipy raises many types on a damaged file: all mean "not readable"
        raise ConfigError(f'{path}: not a readable MATLAB file ({type(exc).__name__}: {exc})') from exc
    missing = [k for k in ('t', 'qm', 'vir', 'gtau') if k not in d]
    if missing:
        raise ConfigError(f'{path}: missing variable(s) {", ".join(missing)}; an EMPS file has t, qm, vir, gtau')
    try:
        cols = [np.asarray(d[k], float).ravel() for k in ('t', 'qm', 'vir', 'gtau')]
    except (TypeError, ValueError) as exc:
        raise ConfigError(f'{path}: variables t, qm, vir, gtau must be numeric arrays ({exc})') from exc
    if len(cols[3]) != 1 or not np.isfinite(cols[3][0]) or cols[3][0] <= 0:
        raise ConfigError(f'{path}: gtau must be one positive number [N/V], got {cols[3][:3]}')
    return check_record(Record(Path(path).name, cols[0], cols[1], cols[2], float(cols[3][0]),
                               normal_force=1.0, stick_velocity=0.0, cutoff_hz=20.0))


def load(path: str | Path, plant: PlantParams | None, columns: dict | None = None,
         cart_alone: bool = False, angle_zero: str = 'auto') -> Record:
    """Pick the loader from the file: .csv, .mat (EMPS), else a bag (directory or .mcap).

    ``plant`` None: a bag's stored scenario, Table 1 for a CSV. ``angle_zero``: where a CSV's
    angle is measured from (:data:`ANGLE_ZEROS`)."""
    p = Path(path)
    if p.exists() and not (p.is_file() or p.is_dir()):
        raise ConfigError(f'{p}: not a regular file (a FIFO, socket or device would be read without end); give '
                          f'a .csv, an EMPS .mat, a run directory or a bag')
    if p.suffix.lower() == '.csv' or p.name.lower().endswith('.csv.gz'):
        return load_csv(p, plant or PlantParams(), columns, angle_zero, cart_alone)
    if p.suffix.lower() == '.mat':
        return load_emps(p)
    if not p.exists():
        raise ConfigError(f'{p}: no such file or directory (give a .csv, an EMPS .mat, a run directory '
                          f'or a bag)')
    return load_bag(p, plant, cart_alone)


def trajectory_record(name: str, traj, plant: PlantParams, cart_alone: bool = False) -> Record:
    """A :class:`closedloop.Trajectory` as measured data (encoders and commands only)."""
    return _rig_record(name, traj.t, traj.measured[:, 0], traj.voltage,
                       None if cart_alone else traj.measured[:, 1], plant)


def write_csv(path: str | Path, rec: Record) -> Path:
    """Write ``rec`` as a CSV table t,x,voltage[,theta] (the format :func:`load_csv` reads)."""
    path = Path(path)
    cols = [rec.t, rec.x, rec.u] + ([rec.theta] if rec.theta is not None else [])
    header = 't,x,voltage' + (',theta' if rec.theta is not None else '')
    np.savetxt(path, np.column_stack(cols), delimiter=',', header=header, comments='', fmt='%.9g')
    return path
