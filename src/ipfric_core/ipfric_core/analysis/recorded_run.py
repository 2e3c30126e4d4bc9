"""Offline analysis of recorded runs: class, amplitude, period, sticking, plots."""
from __future__ import annotations

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
from .bagread import RunData, read_run
from .oscillation import classify
from .plots import overlay_figure, run_figure


def _resolution(run: RunData) -> tuple[float, float]:
    sim = (run.config or {}).get('sim', {})
    return sim.get('cart_resolution', CART_RESOLUTION_M), sim.get('angle_resolution', ANGLE_RESOLUTION_RAD)


def run_name(path: str | Path) -> str:
    """A figure name for a run: the first path part that is not a generic ``run``, ``bag``, ``bag_0.mcap``."""
    p = Path(path).resolve()
    while p.parent != p and re.fullmatch(r'(run|bag)(_\d+)?', p.name.removesuffix('.mcap')):
        p = p.parent
    return p.name.removesuffix('.mcap') or 'run'


def analyze_run(path: str | Path, plot_dir: str | Path | None = None, window: float = 10.0) -> dict:
    """Classify one run from its bag; write its figure to ``plot_dir`` if given."""
    run = read_run(path, keep=(JOINT_STATES,) if plot_dir is None else (JOINT_STATES, VOLTAGE_COMMAND, PLANT_STATE))
    sim = (run.config or {}).get('sim', {})
    fallen = sim.get('fallen_angle', FALLEN_ANGLE_RAD)
    ended = run.end_reason in LIMITS
    if len(run.t) < 2:
        return {'path': str(path), 'class': None, 'samples': int(len(run.t)), 'truncated': run.truncated,
                'truncation_detail': run.truncation_detail, 'damage': run.damage, 'error': 'fewer than 2 samples'}
    o = classify(run.t, run.x, run.theta, _resolution(run), fallen, ended_fallen=ended,
                 window=min(window, 0.5 * float(run.t[-1] - run.t[0]) or window))
    out = {'path': str(path), 'samples': int(len(run.t)), 'duration_s': float(run.t[-1] - run.t[0]),
           'end_reason': run.end_reason, 'truncated': run.truncated,
           'truncation_detail': run.truncation_detail, 'damage': run.damage, 'counts': run.counts,
           'gain': run.gain,
           **{('class' if k == 'cls' else k): v for k, v in o.to_dict().items()}}
    if plot_dir is not None:
        d = Path(plot_dir)
        d.mkdir(parents=True, exist_ok=True)
        name = run_name(path)
        title = f'{name}: {o.cls.replace("_", " ")}'
        if o.period_crossings:
            title += f', x p2p {o.x_p2p * 100:.2f} cm, period {o.period_crossings:.2f} s'
        phase = (run.truth['theta'], run.truth['theta_dot']) if len(run.truth_t) else None
        out['figure'] = str(run_figure(run.t, run.x, run.theta, run.command_t, run.voltage, title,
                                       d / f'{name}.png', phase))
    return out


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


def overlay_runs(paths, plot_path: str | Path) -> dict:
    """Overlay the cart position of several runs, each aligned on the first."""
    runs = [read_run(p) for p in paths]
    ref = runs[0]
    shifts = [(0.0, 0.0)] + [alignment_shift(ref.t, ref.x, r.t, r.x) for r in runs[1:]]
    fig = overlay_figure([(r.t, r.x) for r in runs], [Path(p).name for p in paths], shifts, plot_path)
    return {'figure': str(fig), 'shifts': [{'path': str(p), 'time_s': s[0], 'position_m': s[1]}
                                           for p, s in zip(paths, shifts)]}
