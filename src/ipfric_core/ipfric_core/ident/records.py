"""Measured data for identification: one record type and its loaders.

A :class:`Record` is a sampled experiment on a prismatic axis: time t [s], position
x [m], the input u in its own unit (V) with the factor ``gain`` that turns it into a
force [N/unit], and, when a pendulum is attached, its angle theta [rad from upright].
Loaders: a run bag of ``./ipfric run`` (measured topics only: encoders and commands),
a CSV table, the EMPS benchmark files (force ``gtau * vir``, position ``qm``).
Bad input is refused with a :class:`ConfigError` naming the problem.
"""
from __future__ import annotations

import csv
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..physics.params import ConfigError, PlantParams

MIN_SAMPLES = 200


@dataclass(frozen=True)
class Record:
    """One experiment (SI units).

    gain : N per unit of u (alpha [N/V] for the rig, gtau for EMPS)
    back_emf : known velocity damping of the drive [N s/m] (beta of eq. 2; 0 if unknown)
    pendulum : (m [kg], l [m], g [m/s^2]) when theta is measured, else None
    normal_force : F_N [N] used to express friction as coefficients mu
    stick_velocity : |x'| [m/s] below which a sample counts as stuck (left out of the fit)
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

    @property
    def dt(self) -> float:
        return float(np.median(np.diff(self.t)))

    def split(self, fraction: float) -> tuple['Record', 'Record']:
        """(first ``fraction``, rest) in time: estimation and validation parts."""
        k = int(round(fraction * len(self.t)))
        parts = []
        for sl, tag in ((slice(0, k), 'estimation'), (slice(k, None), 'validation')):
            parts.append(replace(self, name=f'{self.name} ({tag})', t=self.t[sl], x=self.x[sl], u=self.u[sl],
                                 theta=None if self.theta is None else self.theta[sl]))
        return parts[0], parts[1]


def check_record(rec: Record) -> Record:
    """Refuse NaN, non-monotonic time, too few samples and ranges that betray wrong units."""
    n = len(rec.t)
    arrays = {'t': rec.t, 'x': rec.x, 'u': rec.u}
    if rec.theta is not None:
        arrays['theta'] = rec.theta
    for k, a in arrays.items():
        if len(a) != n:
            raise ConfigError(f'{rec.name}: column {k} has {len(a)} samples, t has {n}')
        bad = np.nonzero(~np.isfinite(a))[0]
        if len(bad):
            raise ConfigError(f'{rec.name}: column {k} is NaN or infinite at row {bad[0]} '
                              f'({len(bad)} such rows); clean or cut the data')
    if n < MIN_SAMPLES:
        raise ConfigError(f'{rec.name}: {n} samples is too short; at least {MIN_SAMPLES} are needed')
    d = np.diff(rec.t)
    if np.any(d <= 0):
        i = int(np.nonzero(d <= 0)[0][0])
        raise ConfigError(f'{rec.name}: time is not increasing at row {i + 1} '
                          f'(t = {rec.t[i]:g} then {rec.t[i + 1]:g} s)')
    if np.max(d) > 1.5 * np.min(d) + 1e-9:
        raise ConfigError(f'{rec.name}: samples are not evenly spaced (dt from {np.min(d):g} to '
                          f'{np.max(d):g} s); resample to a constant period')
    if np.ptp(rec.x) > 20.0:
        raise ConfigError(f'{rec.name}: x spans {np.ptp(rec.x):g}; expected metres (a prismatic axis '
                          f'moves less than 20 m); is it in mm or counts?')
    if np.ptp(rec.x) == 0.0:
        raise ConfigError(f'{rec.name}: x never changes; nothing moved')
    if rec.t[-1] - rec.t[0] > 1e5:
        raise ConfigError(f'{rec.name}: t spans {rec.t[-1] - rec.t[0]:g}; expected seconds (ms or ns?)')
    if rec.theta is not None and np.max(np.abs(rec.theta)) > 2 * np.pi:
        raise ConfigError(f'{rec.name}: |theta| reaches {np.max(np.abs(rec.theta)):g}; expected radians '
                          f'from upright (degrees?)')
    return rec


def _rig_record(name, t, x, u, theta, plant: PlantParams) -> Record:
    pend = None if theta is None else (plant.m, plant.l, plant.g)
    fn = plant.normal_force if theta is not None else plant.M * plant.g
    return check_record(Record(name, np.asarray(t, float), np.asarray(x, float), np.asarray(u, float),
                               plant.alpha, plant.beta, None if theta is None else np.asarray(theta, float),
                               pend, fn, stick_velocity=2e-3, cutoff_hz=25.0))


def load_csv(path: str | Path, plant: PlantParams, columns: dict | None = None) -> Record:
    """CSV with a header: t [s], x [m], voltage [V] and optionally theta [rad from upright].

    ``columns`` maps these names to the file's headers, e.g. {'x': 'cart_m'}.
    """
    path = Path(path)
    cols = {'t': 't', 'x': 'x', 'voltage': 'voltage', 'theta': 'theta'}
    unknown = set(columns or {}) - set(cols)
    if unknown:
        raise ConfigError(f'column mapping: unknown name(s) {", ".join(sorted(unknown))}; '
                          f'allowed: t, x, voltage, theta')
    cols.update(columns or {})
    try:
        lines = [ln for ln in path.read_text().splitlines() if ln.strip() and not ln.startswith('#')]
    except OSError as exc:
        raise ConfigError(f'{path}: cannot read ({exc.strerror})') from exc
    if not lines:
        raise ConfigError(f'{path}: empty file; expected a header t,x,voltage[,theta]')
    reader = csv.reader(lines)
    header = [h.strip() for h in next(reader)]
    for need in ('t', 'x', 'voltage'):
        if cols[need] not in header:
            raise ConfigError(f'{path}: missing column {cols[need]!r} ({need}); header has '
                              f'{", ".join(header)}; map columns with --columns {need}=NAME')
    rows = list(reader)
    try:
        data = np.array([[float(v) if v.strip() else np.nan for v in r] for r in rows], float)
    except ValueError as exc:
        raise ConfigError(f'{path}: non-numeric value ({exc})') from exc
    if data.ndim != 2 or data.shape[1] != len(header):
        raise ConfigError(f'{path}: rows do not all have {len(header)} fields')

    def col(name):
        return data[:, header.index(cols[name])]
    theta = col('theta') if cols['theta'] in header else None
    return _rig_record(path.name, col('t'), col('x'), col('voltage'), theta, plant)


def load_bag(path: str | Path, plant: PlantParams | None = None, cart_alone: bool = False) -> Record:
    """A run of ``./ipfric run``: encoders (joint_states) and commands (voltage_command) only.

    The command of sample k has the stamp of the measurement it answers and is held over
    [t_k, t_k+1). The plant constants come from ``plant`` or else the run's stored
    scenario (the design side: alpha, beta, masses; never the friction or the truth).
    """
    from ..analysis.bagread import read_run
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
    return _rig_record(Path(path).name, run.t[idx], run.x[idx], run.voltage[ok],
                       None if cart_alone else run.theta[idx], plant)


def load_emps(path: str | Path) -> Record:
    """EMPS benchmark .mat: force input gtau * vir [N], motor position on the load side qm [m]."""
    from scipy.io import loadmat
    try:
        d = loadmat(str(path))
    except (OSError, ValueError) as exc:
        raise ConfigError(f'{path}: not a readable MATLAB file ({exc})') from exc
    missing = [k for k in ('t', 'qm', 'vir', 'gtau') if k not in d]
    if missing:
        raise ConfigError(f'{path}: missing variable(s) {", ".join(missing)}; an EMPS file has t, qm, vir, gtau')
    return check_record(Record(Path(path).name, d['t'].ravel().astype(float), d['qm'].ravel().astype(float),
                               d['vir'].ravel().astype(float), float(d['gtau'].ravel()[0]),
                               normal_force=1.0, stick_velocity=0.0, cutoff_hz=20.0))


def load(path: str | Path, plant: PlantParams | None, columns: dict | None = None,
         cart_alone: bool = False) -> Record:
    """Pick the loader from the file: .csv, .mat (EMPS), else a bag (directory or .mcap).

    ``plant`` None: a bag's stored scenario, Table 1 for a CSV."""
    p = Path(path)
    if p.suffix.lower() == '.csv':
        return load_csv(p, plant or PlantParams(), columns)
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
