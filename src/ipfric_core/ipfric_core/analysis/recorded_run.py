"""Offline analysis of recorded runs and rig logs: class, amplitude, period, sticking, plots.

A run's bag (:func:`analyze_run`) is judged by its final regime; a rig's log (CSV or
MATLAB, :func:`analyze_log`) is cut into the stretches where the pendulum is balanced
and each into regimes (:func:`ipfric_core.analysis.oscillation.regimes`).
"""
from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np

from ..constants import (
    ANGLE_RESOLUTION_RAD,
    CART_RESOLUTION_M,
    FALLEN_ANGLE_RAD,
    JOINT_STATES,
    LIMITS,
    PLANT_STATE,
    VOLTAGE_COMMAND,
)
from ..physics.params import ConfigError
from .bagread import RunData, read_run
from .oscillation import balanced_segments, classify, regime_of, regimes
from .plots import overlay_figure, run_figure
from .records import gap_starts, load, smallest_step

__all__ = ['LOOP_PARAMETERS', 'parameter_changes', 'parameter_regimes', 'analyze_run', 'overlay_runs', 'analyze_log']


def _resolution(run: RunData) -> tuple[float, float]:
    sim = (run.config or {}).get('sim', {})
    return sim.get('cart_resolution', CART_RESOLUTION_M), sim.get('angle_resolution', ANGLE_RESOLUTION_RAD)


def run_name(path: str | Path) -> str:
    """A figure name for a run: the first path part that is not a generic ``run``, ``bag``, ``bag_0.mcap``."""
    p = Path(path).resolve()
    while p.parent != p and re.fullmatch(r'(run|bag)(_\d+)?', p.name.removesuffix('.mcap')):
        p = p.parent
    return p.name.removesuffix('.mcap') or 'run'


#: Controller parameters whose run-time change starts a new regime of the loop.
LOOP_PARAMETERS = ('delay', 'gain', 'cutoff_hz', 'voltage_limit')


def parameter_changes(run: RunData) -> list[dict]:
    """The run-time changes of the controller's loop parameters in the bag (``/parameter_events``):
    simulated time [s], node, parameter, the value before (the run's configuration, or the change
    before) and after."""
    before = dict((run.config or {}).get('controller', {}))
    before['gain'] = (run.config or {}).get('gain')
    out = []
    for t, node, name, value in run.parameter_changes:
        if name in LOOP_PARAMETERS and node.endswith('/controller_node'):
            out.append({'t': float(t), 'node': node, 'parameter': name, 'before': before.get(name), 'after': value})
            before[name] = value
    return out


def parameter_regimes(run: RunData, changes: list[dict], resolution, fallen: float) -> list[dict]:
    """The run cut where a change gave a parameter a new value: each stretch as one regime (class,
    amplitudes, periods) and the changes it starts with."""
    if not changes or len(run.t) < 2:
        return []
    moved = [c for c in changes if c['after'] != c['before']]
    cuts = [float(run.t[0])] + sorted({c['t'] for c in moved if run.t[0] < c['t'] < run.t[-1]}) + [float(run.t[-1])]
    out = []
    for a, b in zip(cuts, cuts[1:]):
        if b - a < 2 * (run.t[1] - run.t[0]):
            continue
        out.append({**regime_of(run.t, run.x, run.theta, a, b, resolution, fallen).to_dict(),
                    'after': [f'{c["parameter"]} {c["after"]}' for c in moved if c['t'] == a]})
    return out


def analyze_run(path: str | Path, plot_dir: str | Path | None = None, window: float = 10.0,
                namespace: str | None = None) -> dict:
    """Classify one run from its bag (the rig of ``namespace`` in a bag of several); write its
    figure to ``plot_dir`` if given. A run whose controller parameters changed while it ran is
    also cut at each change into regimes (``parameter_regimes``)."""
    run = read_run(path, keep=(JOINT_STATES,) if plot_dir is None else (JOINT_STATES, VOLTAGE_COMMAND, PLANT_STATE),
                   namespace=namespace)
    sim = (run.config or {}).get('sim', {})
    fallen = sim.get('fallen_angle', FALLEN_ANGLE_RAD)
    ended = run.end_reason in LIMITS
    if len(run.t) < 2:
        return {'path': str(path), 'class': None, 'samples': int(len(run.t)), 'truncated': run.truncated,
                'truncation_detail': run.truncation_detail, 'damage': run.damage, 'incomplete': run.incomplete,
                'error': 'fewer than 2 samples'}
    o = classify(run.t, run.x, run.theta, _resolution(run), fallen, ended_fallen=ended,
                 window=min(window, 0.5 * float(run.t[-1] - run.t[0]) or window))
    changes = parameter_changes(run)
    spans = parameter_regimes(run, changes, _resolution(run), fallen)
    out = {'path': str(path), 'namespace': run.namespace, 'samples': int(len(run.t)),
           'duration_s': float(run.t[-1] - run.t[0]), 'end_reason': run.end_reason, 'end_detail': run.end_event[1],
           'truncated': run.truncated,
           'truncation_detail': run.truncation_detail, 'damage': run.damage, 'incomplete': run.incomplete,
           'counts': run.counts, 'gain': run.gain, 'parameter_changes': changes, 'parameter_regimes': spans,
           **{('class' if k == 'cls' else k): v for k, v in o.to_dict().items()}, **loop_timing(path)}
    if plot_dir is not None:
        d = Path(plot_dir)
        d.mkdir(parents=True, exist_ok=True)
        name = run_name(path)
        title = f'{name}: {o.cls.replace("_", " ")}'
        if o.period_crossings:
            title += f', x p2p {o.x_p2p * 100:.2f} cm, period {o.period_crossings:.2f} s'
        phase = (run.truth['theta'], run.truth['theta_dot']) if len(run.truth_t) else None
        out['figure'] = str(run_figure(run.t, run.x, run.theta, run.command_t, run.voltage, title,
                                       d / f'{name}.png', phase, [(r['start'], r['end'], r['cls']) for r in spans]))
    return out


def loop_timing(path: str | Path) -> dict:
    """What sim_node measured of the loop (``sim_result.json`` of a run directory, beside
    or above the bag): time mode, samples at which no fresh command had arrived (the held
    command was applied: an extra sample of delay the plant saw) and the command latency
    [s]; empty for a bag without it."""
    p = Path(path)
    for d in (p, p.parent, p.parent.parent):
        f = d / 'sim_result.json'
        if f.is_file():
            try:
                sim = json.loads(f.read_text())
            except ValueError:
                return {}
            return {k: sim.get(k) for k in ('time_mode', 'samples_without_command', 'command_latency_s')}
    return {}


def alignment_shift(t_ref, x_ref, t, x) -> tuple[float, float]:
    """(time [s], position [m]) shift of run (t, x) that best overlays it on the reference.

    The time shift maximizes the cross-correlation of the mean-removed positions on a
    common 1 kHz grid (limited to +/- half the shorter run); the position shift then
    matches the means, since the cart's final position is arbitrary (paper, Figure 7).
    """
    dt = 1e-3
    tg = np.arange(max(t_ref[0], t[0]), min(t_ref[-1], t[-1]), dt)
    if len(tg) < 10:
        return 0.0, float(np.mean(x_ref) - np.mean(x))
    a = np.interp(tg, t_ref, x_ref)
    b = np.interp(tg, t, x)
    a, b = a - a.mean(), b - b.mean()
    corr = np.correlate(a, b, mode='full')
    lags = np.arange(-len(b) + 1, len(a))
    keep = np.abs(lags) <= len(tg) // 2
    lag = int(lags[keep][np.argmax(corr[keep])])
    shift_t = lag * dt
    shifted = np.interp(tg, t + shift_t, x)
    valid = (tg >= t[0] + shift_t) & (tg <= t[-1] + shift_t)
    shift_x = float(np.mean(np.interp(tg, t_ref, x_ref)[valid]) - np.mean(shifted[valid])) if valid.any() else 0.0
    return shift_t, shift_x


def overlay_runs(paths, plot_path: str | Path, namespace: str | None = None) -> dict:
    """Overlay the cart position of several runs, each aligned on the first."""
    runs = [read_run(p, namespace=namespace) for p in paths]
    ref = runs[0]
    shifts = [(0.0, 0.0)] + [alignment_shift(ref.t, ref.x, r.t, r.x) for r in runs[1:]]
    fig = overlay_figure([(r.t, r.x) for r in runs], [Path(p).name for p in paths], shifts, plot_path)
    return {'figure': str(fig), 'shifts': [{'path': str(p), 'time_s': s[0], 'position_m': s[1]}
                                           for p, s in zip(paths, shifts)]}


def analyze_log(path: str | Path, columns: dict | None = None, angle_zero: str = 'auto',
                max_angle: float = math.radians(20.0), min_duration: float = 2.0,
                plot_dir: str | Path | None = None) -> dict:
    """A rig's log (the formats of ``identify``: CSV t, x, voltage, theta; ``columns``
    maps names to headers) cut into balanced stretches (|theta| < ``max_angle`` [rad] for
    at least ``min_duration`` [s], none across a gap in the log), each into regimes: class, time span, cart and angle
    peak-to-peak, period by zero crossings and by spectrum, sticking."""
    rec = load(path, None, columns, angle_zero=angle_zero)
    if rec.theta is None:
        raise ConfigError(f'{path}: no pendulum angle in the file; analyze needs t, x and theta '
                          f'(map a CSV column with --columns theta=NAME)')
    theta = rec.theta
    zero = 'hanging' if any('hanging' in n for n in rec.notes) else 'upright'
    resolution = (smallest_step(rec.x, 0.0), smallest_step(theta, 0.0))
    segments = []
    for a, b in balanced_segments(rec.t, theta, max_angle, min_duration, gap_starts(rec.t)):
        parts = regimes(rec.t[a:b], rec.x[a:b], theta[a:b], resolution)
        segments.append({'start': float(rec.t[a]), 'end': float(rec.t[b - 1]), 'class': parts[-1].cls,
                         'regimes': [r.to_dict() for r in parts]})
    out = {'path': str(path), 'samples': int(len(rec.t)), 'duration_s': float(rec.t[-1] - rec.t[0]),
           'sample_period_s': rec.dt, 'angle_zero': zero, 'count_size': list(resolution), 'segments': segments,
           'notes': list(rec.notes)}
    if plot_dir is not None:
        d = Path(plot_dir)
        d.mkdir(parents=True, exist_ok=True)
        spans = [(r['start'], r['end'], r['cls']) for s in segments for r in s['regimes']]
        out['figure'] = str(run_figure(rec.t, rec.x, theta, rec.t, rec.u, f'{Path(path).name}: {len(segments)} '
                                       f'balanced stretch(es)', d / f'{Path(path).stem}.png', spans=spans))
    return out
