"""Sweeps of a scenario's closed loop: stability maps over the artificial delay tau and the
initial angle theta0 (Figures 11-12), the oscillation against encoder resolution (section 6)
and the threshold angle between convergence and the periodic orbit (Figure 8b).

Each cell is one closed-loop run of a scenario with the controller delay and theta0
replaced (:func:`ipfric_core.study.variants.cell_scenario`), classified by
:func:`ipfric_core.study.outcome.classify_run`. Cells run in parallel processes (local, or on a
Dask cluster: ``scheduler``, :mod:`ipfric_core.study.executor`), are appended to ``cells.csv``
as they finish (so an interrupted sweep resumes without redoing them), and are deterministic:
a cell's result depends only on its inputs. The ``*_study`` functions run a sweep and write its
summary (JSON) and figure into an output directory.
"""
from __future__ import annotations

import csv
import json
import math
import shutil
from collections.abc import Callable
from concurrent.futures import as_completed
from dataclasses import replace
from pathlib import Path

import numpy as np
import yaml

from ..analysis.bagread import read_run
from ..analysis.oscillation import CLASSES
from ..constants import LIMITS
from ..physics.params import ConfigError
from ..run.runner import EXIT_FELL, run
from ..run.scenario import Scenario
from .executor import make_executor
from .maps import resolution_figure, stability_map, transition_figure
from .outcome import classify_run, classify_samples, true_p2p
from .variants import (
    FIGURE_GRIDS,
    FIGURES,
    SCALED_SENSORS,
    cell_scenario,
    figure_config,
    load_variant,
    scaled_encoders,
    scenario_at,
)

__all__ = ['FIELDS', 'sweep', 'grid', 'boundaries', 'parse_range', 'resolution_study', 'threshold_angle', 'map_study',
           'figure_study', 'resolution_report', 'threshold_report']

FIELDS = ('tau_s', 'theta0_deg', 'class', 'transition_time_s', 'x_p2p_m', 'theta_p2p_rad', 'period_s')


def run_cell(base: Scenario, tau: float, theta0_deg: float, duration: float,
             ros_dir: str | Path | None = None) -> dict:
    """Run and classify one cell; returns a CSV row.

    With ``ros_dir`` the cell runs through the ROS 2 loop in lockstep (``./ipfric run``
    into ``ros_dir/<cell>``) and is classified from its bag; otherwise the offline core runs it.
    """
    scn = cell_scenario(base, tau, theta0_deg)
    if ros_dir is None:
        o, _ = classify_run(scn, duration)
    else:
        o = classify_samples(scn, *_ros_cell(scn, Path(ros_dir) / f'tau{tau:.4f}_theta{theta0_deg:.4f}', duration))
    return {'tau_s': round(tau, 9), 'theta0_deg': round(theta0_deg, 9), 'class': o.cls,
            'transition_time_s': o.transition_time, 'x_p2p_m': o.x_p2p, 'theta_p2p_rad': o.theta_p2p,
            'period_s': o.period_crossings}


def _ros_cell(scn: Scenario, cell_dir: Path, duration: float):
    """(t, x, theta, ended by a limit) of one lockstep ROS run of ``scn``."""
    if cell_dir.exists():          # a cell interrupted before it reached cells.csv: run it again
        shutil.rmtree(cell_dir)
    cell_dir.mkdir(parents=True)
    params = replace(scn, sim=replace(scn.sim, time_mode='lockstep')).to_ros_params()
    cfg = cell_dir / 'cell.yaml'
    cfg.write_text(yaml.safe_dump(params, sort_keys=False))
    res = run(cfg, cell_dir / 'run', duration=duration, timeout=60.0 + 2.0 * duration)
    if res.exit_code not in (0, EXIT_FELL):
        raise RuntimeError(f'ROS run of {cell_dir.name} failed:\n{res.summary()}')
    bag = read_run(res.bag)
    return bag.t, bag.x, bag.theta, bag.end_reason in LIMITS


def _key(tau, theta0_deg) -> tuple:
    return (round(float(tau), 9), round(float(theta0_deg), 9))


def load_cells(path: Path) -> dict:
    """Finished cells of an earlier (possibly interrupted) sweep; a torn last line is ignored."""
    done: dict[tuple, dict] = {}
    if not path.exists():
        return done
    with open(path, newline='') as fh:
        for row in csv.DictReader(fh):
            try:
                if row['class'] not in CLASSES:
                    continue
                typed: dict[str, object] = {k: (None if row[k] in ('', None) else float(row[k]))
                                            for k in FIELDS if k != 'class'}
                typed['class'] = row['class']
                done[_key(typed['tau_s'], typed['theta0_deg'])] = typed
            except (KeyError, TypeError, ValueError):
                continue
    return done


def sweep(base: Scenario, taus, thetas_deg, duration: float, out_dir: str | Path,
          workers: int | None = None, progress: Callable[[int, int], None] | None = None,
          ros: bool = False, scheduler: str | None = None) -> list[dict]:
    """Run every (tau, theta0) cell not already in ``out_dir/cells.csv``; return all rows sorted.

    ``ros``: each cell through the ROS 2 loop in lockstep (bags kept in ``out_dir/ros``;
    one cell at a time unless ``workers`` says otherwise, each cell being three processes).
    ``scheduler``: the cells run on that Dask cluster (:func:`ipfric_core.study.executor.make_executor`).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    path = out / 'cells.csv'
    done = load_cells(path)
    todo = [(t, th) for th in thetas_deg for t in taus if _key(t, th) not in done]
    total = len(taus) * len(thetas_deg)
    new_file = not path.exists() or not done
    with open(path, 'w' if new_file else 'a', newline='') as fh:
        w = csv.DictWriter(fh, FIELDS)
        if new_file:
            w.writeheader()
        finished = total - len(todo)
        if progress:
            progress(finished, total)
        ros_dir = out / 'ros' if ros else None
        with make_executor(scheduler, workers or (1 if ros else None)) as pool:
            futures = [pool.submit(run_cell, base, t, th, duration, ros_dir) for t, th in todo]
            for fut in as_completed(futures):
                row = fut.result()
                w.writerow(row)
                fh.flush()
                done[_key(row['tau_s'], row['theta0_deg'])] = row
                finished += 1
                if progress:
                    progress(finished, total)
    rows = [done[_key(t, th)] for th in thetas_deg for t in taus]
    with open(path, 'w', newline='') as fh:  # rewrite in grid order: same inputs, same file
        w = csv.DictWriter(fh, FIELDS)
        w.writeheader()
        w.writerows(rows)
    return rows


def grid(rows, taus, thetas_deg) -> list[list[str]]:
    """Classes as a theta0-by-tau table."""
    by = {_key(r['tau_s'], r['theta0_deg']): r['class'] for r in rows}
    return [[by[_key(t, th)] for t in taus] for th in thetas_deg]


def boundaries(rows, taus, thetas_deg) -> list[dict]:
    """Per theta0: the largest tau still settled, the smallest not settled, the smallest that falls."""
    g = grid(rows, taus, thetas_deg)
    out = []
    for th, row in zip(thetas_deg, g):
        settled = [t for t, c in zip(taus, row) if c == 'settled']
        unsettled = [t for t, c in zip(taus, row) if c != 'settled']
        fallen = [t for t, c in zip(taus, row) if c == 'fallen']
        out.append({'theta0_deg': float(th), 'last_settled_tau_s': max(settled) if settled else None,
                    'first_unsettled_tau_s': min(unsettled) if unsettled else None,
                    'first_fallen_tau_s': min(fallen) if fallen else None})
    return out


def parse_range(text: str) -> np.ndarray:
    """'start:stop:step' (stop included) or 'a,b,c' -> array."""
    try:
        if ':' in text:
            a, b, s = (float(v) for v in text.split(':'))
            if s <= 0 or b < a:
                raise ValueError
            n = int(math.floor((b - a) / s + 1e-9)) + 1
            return np.round(a + s * np.arange(n), 9)
        return np.array([float(v) for v in text.split(',')])
    except ValueError as exc:
        raise ValueError(f'range {text!r}: expected start:stop:step with step > 0 and stop >= start, '
                         f'or a comma-separated list of numbers') from exc


def resolution_cell(base: Scenario, scale: float, duration: float, sensor: str = 'angle') -> dict:
    """One run with the ``sensor`` encoder count(s) multiplied by ``scale`` (0 = exact)."""
    scn = scaled_encoders(base, scale, sensor)
    o, tr = classify_run(scn, duration)
    true_x, true_theta = true_p2p(o, tr)
    return {'scale': float(scale), 'cart_resolution_m': scn.sim.cart_resolution,
            'angle_resolution_rad': scn.sim.angle_resolution, 'class': o.cls,
            'x_p2p_m': o.x_p2p, 'theta_p2p_rad': o.theta_p2p, 'period_s': o.period_crossings,
            'true_x_p2p_m': true_x, 'true_theta_p2p_rad': true_theta}


def resolution_study(base: Scenario, scales, duration: float, sensor: str = 'angle',
                     workers: int | None = None, scheduler: str | None = None) -> list[dict]:
    """Oscillation against encoder resolution (section 6), one run per scale of the scenario's count(s);
    in local processes, or on the Dask cluster at ``scheduler``."""
    n = len(scales)
    with make_executor(scheduler, workers) as pool:
        return list(pool.map(resolution_cell, [base] * n, scales, [duration] * n, [sensor] * n))


def angle_class(base: Scenario, theta0: float, duration: float, window: float):
    """The Oscillation of ``base`` run offline from the initial angle ``theta0`` [rad]."""
    return classify_run(scenario_at(base, 'theta0', theta0), duration, window)[0]


def threshold_angle(base: Scenario, lo: float, hi: float, duration: float, rtol: float = 0.01,
                    window: float = 20.0, progress: Callable[[float, float], None] | None = None,
                    scheduler: str | None = None) -> dict:
    """Bisect the initial angle [rad] separating convergence from the periodic orbit.

    Requires the run from ``lo`` to settle and the run from ``hi`` not to (Figure 8(b):
    bistability of the equilibrium and a limit cycle). Stops when hi - lo < rtol * hi.
    The two bracket runs go in parallel, then one run per bisection step, in local
    processes or on the Dask cluster at ``scheduler``.
    """
    with make_executor(scheduler, 2) as pool:
        c_lo, c_hi = pool.map(angle_class, [base] * 2, [lo, hi], [duration] * 2, [window] * 2)
        if c_lo.cls != 'settled' or c_hi.cls == 'settled':
            raise ValueError(f'theta0 = {lo:g} rad gives {c_lo.cls} and {hi:g} rad gives {c_hi.cls}: '
                             f'the bracket must go from settled to not settled')
        runs = 2
        while hi - lo > rtol * hi:
            mid = math.sqrt(lo * hi) if lo > 0 else 0.5 * hi
            o = pool.submit(angle_class, base, mid, duration, window).result()
            runs += 1
            if o.cls == 'settled':
                lo = mid
            else:
                hi, c_hi = mid, o
            if progress:
                progress(lo, hi)
    return {'settles_below_rad': lo, 'oscillates_from_rad': hi, 'runs': runs,
            'hi_class': c_hi.cls, 'hi_x_p2p_m': c_hi.x_p2p, 'hi_period_s': c_hi.period_crossings}


def _write_json(out: Path, name: str, obj: dict) -> Path:
    out.mkdir(parents=True, exist_ok=True)
    path = out / name
    path.write_text(json.dumps(obj, indent=2, default=float))
    return path


def map_study(config, taus, thetas_deg, duration: float, out: str | Path, sensors: str = 'exact',
              smoothing: str | None = None, cutoff_hz: float | None = None, workers: int | None = None,
              progress: Callable[[int, int], None] | None = None, ros: bool = False,
              scheduler: str | None = None) -> dict:
    """The stability map of scenario file ``config`` (its :func:`~ipfric_core.study.variants.load_variant`)
    over ``taus`` [s] and ``thetas_deg`` [deg]: ``out/cells.csv``, ``out/map.png``, ``out/summary.json``."""
    base = load_variant(config, sensors, smoothing, cutoff_hz)
    out = Path(out)
    rows = sweep(base, taus, thetas_deg, duration, out, workers, progress, ros=ros, scheduler=scheduler)
    title = f'{Path(config).stem}: {base.friction.model}' + (
        f', tanh({base.friction.delta:g} v)' if base.friction.smoothing == 'tanh' else '')
    fig = stability_map(taus, thetas_deg, grid(rows, taus, thetas_deg), title, out / 'map.png')
    summary = {'config': str(config), 'sensors': sensors, 'duration_s': duration,
               'path': 'ros lockstep' if ros else 'offline', 'cells': len(rows), 'figure': str(fig),
               'csv': str(out / 'cells.csv'), 'counts': {c: sum(r['class'] == c for r in rows) for c in CLASSES},
               'boundaries': boundaries(rows, taus, thetas_deg)}
    _write_json(out, 'summary.json', summary)
    return summary


def figure_study(figure: str, taus, duration: float, out: str | Path, sensors: str = 'exact',
                 cutoff_hz: float | None = None, workers: int | None = None,
                 progress: Callable[[int, int], None] | None = None, say: Callable[[str], None] | None = None,
                 ros: bool = False, scheduler: str | None = None) -> dict:
    """The paper's Figure ``figure`` (a key of :data:`~ipfric_core.study.variants.FIGURES`): each variant
    swept over the full and the zoomed theta0 grid, transition lines on the maps (``figureN.png``),
    ``summary.json``."""
    name, variants = FIGURES[figure]
    config = figure_config(figure)
    out = Path(out)
    panels: list[dict] = []
    result: dict = {'figure_of_paper': figure, 'config': str(config), 'variants': {}}
    for gname, trange in FIGURE_GRIDS:
        ths = parse_range(trange)
        panel: dict = {'title': f'θ0 {ths[0]:g}-{ths[-1]:g} deg', 'taus': taus, 'thetas_deg': ths, 'curves': []}
        for label, smoothing, style in variants:
            base = load_variant(config, sensors, smoothing, cutoff_hz)
            d = out / f'{gname}_{smoothing or "model"}'
            if say:
                say(f'{label}, {gname} grid -> {d}')
            rows = sweep(base, taus, ths, duration, d, workers, progress, ros=ros, scheduler=scheduler)
            b = boundaries(rows, taus, ths)
            panel.setdefault('classes', grid(rows, taus, ths))
            panel['curves'].append((label, style, ths, [r['first_unsettled_tau_s'] for r in b],
                                    [r['first_fallen_tau_s'] for r in b]))
            result['variants'].setdefault(label, {})[gname] = {'csv': str(d / 'cells.csv'), 'boundaries': b}
        panels.append(panel)
    title = f'Figure {figure}: {name.removesuffix(".yaml")}, {sensors} sensors, {duration:g} s runs'
    result['figure'] = str(transition_figure(panels, title, out / f'figure{figure}.png'))
    _write_json(out, 'summary.json', result)
    return result


def resolution_report(config, scales_text: str, duration: float, out: str | Path, sensor: str = 'angle',
                      smoothing: str | None = None, cutoff_hz: float | None = None, workers: int | None = None,
                      scheduler: str | None = None) -> dict:
    """:func:`resolution_study` of scenario file ``config`` at the scales ``scales_text`` (``parse_range``
    syntax; 0 = exact, 1 = the scenario's counts): ``out/resolution.json`` and ``out/resolution.png``."""
    try:
        scales = parse_range(scales_text)
    except ValueError as exc:
        raise ConfigError(f'--resolution-scale: {exc}') from exc
    if (scales < 0).any():
        raise ConfigError('--resolution-scale: scales must be >= 0 (0 = exact sensors, 1 = the scenario\'s)')
    if sensor not in SCALED_SENSORS:
        raise ConfigError(f'--scale-sensor: {sensor!r} is not one of {", ".join(SCALED_SENSORS)}')
    base = load_variant(config, 'config', smoothing, cutoff_hz)
    rows = resolution_study(base, scales, duration, sensor, workers, scheduler)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    fig = resolution_figure(rows, f'{Path(config).stem}: oscillation against {sensor} encoder resolution',
                            out / 'resolution.png')
    summary = {'config': str(config), 'duration_s': duration, 'scaled': sensor, 'rows': rows, 'figure': str(fig)}
    _write_json(out, 'resolution.json', summary)
    return summary


def threshold_report(config, bracket: str, duration: float, out: str | Path, sensors: str = 'exact',
                     smoothing: str | None = None, cutoff_hz: float | None = None,
                     progress: Callable[[float, float], None] | None = None, scheduler: str | None = None) -> dict:
    """:func:`threshold_angle` of scenario file ``config`` in the bracket ``bracket`` ('LO,HI' [rad]):
    ``out/threshold.json``."""
    try:
        lo, hi = (float(v) for v in bracket.split(','))
    except ValueError as exc:
        raise ConfigError(f'--threshold: {bracket!r}: expected LO,HI in rad, e.g. 1e-5,1e-3') from exc
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 <= lo < hi):
        raise ConfigError(f'--threshold: need finite 0 <= LO < HI, got {lo:g}, {hi:g}')
    base = load_variant(config, sensors, smoothing, cutoff_hz)
    try:
        res = threshold_angle(base, lo, hi, duration, progress=progress, scheduler=scheduler)
    except ValueError as exc:
        raise ConfigError(f'--threshold: {exc}') from exc
    res.update(config=str(config), sensors=sensors, cutoff_hz=base.controller.cutoff_hz, duration_s=duration)
    _write_json(Path(out), 'threshold.json', res)
    return res
