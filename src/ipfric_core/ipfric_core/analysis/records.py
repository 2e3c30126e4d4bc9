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

import csv
import gzip
import io
from array import array
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import IO

import numpy as np

from ..physics.params import ConfigError, PlantParams

__all__ = ['Record', 'smallest_step', 'ANGLE_ZEROS', 'is_log', 'parse_columns', 'load', 'trajectory_record']

MIN_SAMPLES = 200
MAX_ROWS = 2_000_000    # a longer CSV is refused (33 min at 1 kHz; identification would take hours)
MAX_VOLTAGE = 1e3       # |u| beyond this is not a drive command [V]
OVERRUN_JUMP = 1.75     # a stamp step this many times the median period starts an overrun
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

    @property
    def dt(self) -> float:
        return float(np.median(np.diff(self.t)))

    @property
    def valid_mask(self) -> np.ndarray:
        return np.ones(len(self.t), bool) if self.valid is None else self.valid

    @property
    def x_resolution(self) -> float:
        """The cart encoder's count [m]: the smallest step of x."""
        return smallest_step(self.x)

    @property
    def theta_resolution(self) -> float:
        """The angle encoder's count [rad]: the smallest step of theta."""
        return smallest_step(self.theta) if self.theta is not None else 1.0

    def split(self, fraction: float) -> tuple[Record, Record]:
        """(first ``fraction``, rest) in time: estimation and validation parts."""
        k = int(round(fraction * len(self.t)))
        parts = []
        for sl, tag in ((slice(0, k), 'estimation'), (slice(k, None), 'validation')):
            parts.append(replace(self, name=f'{self.name} ({tag})', t=self.t[sl], x=self.x[sl], u=self.u[sl],
                                 theta=None if self.theta is None else self.theta[sl],
                                 valid=None if self.valid is None else self.valid[sl]))
        return parts[0], parts[1]


def smallest_step(y, still: float = 1.0) -> float:
    """The smallest nonzero step of a sampled signal: its encoder's count when it is quantized
    (steps below 1e-12 of its size are rounding); ``still`` if it never moves."""
    y = np.asarray(y, float)
    steps = np.abs(np.diff(y))
    steps = steps[steps > 1e-12 * max(1.0, float(np.max(np.abs(y))))] if len(y) else steps
    return float(steps.min()) if len(steps) else still


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


def upright_angle(theta: np.ndarray, zero: str = 'auto') -> tuple[np.ndarray, list[str]]:
    """theta from upright [rad]: unwrapped, and shifted by pi when measured from hanging
    (``zero`` 'hanging', or 'auto' when its median lies more than pi/2 from upright)."""
    if zero not in ANGLE_ZEROS:
        raise ConfigError(f'angle zero {zero!r} is not one of {", ".join(ANGLE_ZEROS)}')
    notes = []
    th = np.unwrap(theta)
    if np.any(np.abs(np.diff(theta)) > np.pi):
        notes.append('angle wrapped at +/-pi: unwrapped')
    turns = np.round(np.median(th) / (2 * np.pi))
    if zero == 'hanging' or (zero == 'auto' and np.median(np.abs(th - 2 * np.pi * turns)) > np.pi / 2):
        th = th - np.pi
        notes.append('angle measured from hanging (pi at upright): mapped to upright = 0')
    turns = np.round(np.median(th) / (2 * np.pi))
    if turns:
        th = th - 2 * np.pi * turns
    return th, notes


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
    if not 1e-5 <= period <= 0.1:
        raise ConfigError(f'{rec.name}: column t has a median sample period of {period:g}; expected seconds '
                          f'between 1e-05 and 0.1 (is t in ms or ns?)')
    if np.ptp(rec.x) > 20.0:
        raise ConfigError(f'{rec.name}: column x spans {np.ptp(rec.x):g}; expected metres (a prismatic axis '
                          f'moves less than 20 m); is it in mm or counts?')
    if np.ptp(rec.x) == 0.0:
        raise ConfigError(f'{rec.name}: column x never changes; nothing moved')
    big = np.flatnonzero(np.abs(rec.u) > MAX_VOLTAGE)
    if len(big):
        raise ConfigError(f'{rec.name}: column voltage is {rec.u[big[0]]:g} at row {big[0] + 1}; allowed '
                          f'|voltage| <= {MAX_VOLTAGE:g} (is it a drive command?)')
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
        theta, found = upright_angle(theta, angle_zero)
        notes += found
    valid = overruns(rec.t, [rec.x] + ([theta] if theta is not None else []))
    if not valid.all():
        notes.append(f'{int((~valid).sum())} stale readings after {int(np.sum(np.diff(valid.astype(int)) == -1))} '
                     f'sample overruns (stamp jump, encoders frozen): not compared')
    if np.max(d) > 1.5 * np.min(d) + 1e-9:
        notes.append(f'uneven stamps (period {np.min(d):g} to {np.max(d):g} s, median {period:g} s): '
                     f'each command held until the next stamp')
    return replace(rec, theta=theta, valid=valid, notes=tuple(notes))


def _rig_record(name, t, x, u, theta, plant: PlantParams, angle_zero: str = 'auto', notes=()) -> Record:
    pend = None if theta is None else (plant.m, plant.l, plant.g)
    fn = plant.normal_force if theta is not None else plant.M * plant.g
    rec = check_record(Record(name, np.asarray(t, float), np.asarray(x, float), np.asarray(u, float),
                              plant.alpha, plant.beta, None if theta is None else np.asarray(theta, float),
                              pend, fn, stick_velocity=2e-3, cutoff_hz=25.0, plant=plant), angle_zero)
    return replace(rec, notes=tuple(notes) + rec.notes)


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
    data = gzip.GzipFile(fileobj=raw) if path.suffix.lower() == '.gz' else raw
    stream = io.TextIOWrapper(data, encoding='utf-8-sig', errors='strict', newline='')
    try:
        yield from enumerate(stream, 1)
    except UnicodeDecodeError as exc:
        raise ConfigError(f'{path}: not a text (UTF-8) CSV file: {exc.reason} near byte {exc.start}') from exc
    except (OSError, EOFError) as exc:
        raise ConfigError(f'{path}: cannot read ({exc})') from exc
    finally:
        stream.close()


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
        if not run.config or 'plant' not in run.config:
            raise ConfigError(f'{path}: the bag stores no scenario; give the plant constants with --plant')
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
