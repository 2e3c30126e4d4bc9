"""Monte Carlo over parameter uncertainty: the distribution of the hunting of a scenario.

N runs of a scenario, each with its parameters drawn at random, each classified like a
sweep cell (:func:`ipfric_core.study.outcome.classify_run`): class, cart and angle
peak-to-peak [m, rad] and period [s] of the final regime. Draws come from
:func:`spread_draw` (relative spreads on plant and friction coefficients) or from an
identification's parameter table (:func:`ipfric_core.ident.uncertainty.report_draw`).

Run i draws from its own generator, seeded by (seed, i): its parameters depend on the
seed and i only, not on N or on where it runs, and its result only on its parameters, so
the rows are the same in local processes and on a Dask cluster (:mod:`ipfric_core.study.executor`).
"""
from __future__ import annotations

import csv
import json
import math
from collections.abc import Callable
from dataclasses import replace
from functools import partial
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from ..analysis.oscillation import CLASSES
from ..analysis.plots import CLASS_COLOURS, save_figure
from ..physics.params import FRICTION_FIELDS, PLANT_FIELDS, ConfigError, Field
from ..run.scenario import SIM_FIELDS, Scenario
from .executor import make_executor, scheduler_address
from .outcome import classify_run, true_p2p

__all__ = ['DISTRIBUTIONS', 'MAX_SEED', 'MIN_RUN_SAMPLES', 'check_seed', 'check_duration', 'parse_spread',
           'spread_draw', 'run_chunk', 'run_montecarlo', 'spread_draws',
           'montecarlo_study']

#: how a relative spread s turns into a factor on the nominal value
DISTRIBUTIONS = ('normal', 'uniform')   # 1 + s z with z ~ N(0, 1), or 1 + s u with u ~ U(-1, 1)
#: coefficients a spread can name: section of the scenario and schema
SPREAD_FIELDS: dict[str, tuple[str, Field]] = {
    **{k: ('plant', f) for k, f in PLANT_FIELDS.items() if k != 'g'},
    **{k: ('friction', f) for k, f in FRICTION_FIELDS.items()
       if k not in ('delta', 'asymmetry', 'asymmetry_viscous')},
}
#: columns of a run's row after its drawn parameters: measured (encoder) and true peak-to-peak
RESULT_FIELDS = ('class', 'transition_time_s', 'x_p2p_m', 'theta_p2p_rad', 'true_x_p2p_m', 'true_theta_p2p_rad',
                 'period_s')
#: classes of a hunting run (a sustained oscillation), whose amplitudes and periods are summarized
HUNTING = ('limit_cycle', 'irregular')
QUANTILES = (0.05, 0.25, 0.5, 0.75, 0.95)
#: runs per task sent to a worker
CHUNK = 25


def parse_spread(text: str) -> dict[str, float]:
    """'mu_s=0.3,mu_c=0.3' -> {'mu_s': 0.3, 'mu_c': 0.3}: relative spreads (0.3 = 30 %)."""
    out: dict[str, float] = {}
    for item in text.split(','):
        name, _, value = item.partition('=')
        name = name.strip()
        if name not in SPREAD_FIELDS:
            raise ConfigError(f'--spread: {name!r} is not a coefficient that can be drawn; allowed: '
                              f'{", ".join(SPREAD_FIELDS)}')
        try:
            s = float(value)
        except ValueError:
            raise ConfigError(f'--spread: {item!r} is not NAME=SPREAD (e.g. mu_s=0.3 for 30 %)') from None
        if not (math.isfinite(s) and 0.0 <= s <= 1.0):
            raise ConfigError(f'--spread: {name} = {value}: the relative spread must be in [0, 1]')
        out[name] = s
    return out


def clip_to_range(value: float, spec: Field) -> float:
    """``value`` inside the schema's range (an open lower bound: just above it)."""
    lo = math.nextafter(spec.lo, math.inf) if spec.lo_open else spec.lo
    return min(max(value, lo), spec.hi)


def spread_draw(base: Scenario, spread: dict[str, float], seed: int, index: int,
                distribution: str = 'normal') -> tuple[dict, Scenario]:
    """Run ``index``'s coefficients: each nominal value times 1 + s z (``DISTRIBUTIONS``), clipped to
    its range, mu_c and mu_s kept in the nominal's order (a Stribeck level that falls with speed, or one
    that rises: eq. 8); (the drawn values, ``base`` with them in plant and friction)."""
    rng = np.random.default_rng([seed, index])
    z = rng.standard_normal(len(spread)) if distribution == 'normal' else rng.uniform(-1.0, 1.0, len(spread))
    sections = {'plant': base.plant, 'friction': base.friction}
    values = {}
    for (name, s), zi in zip(sorted(spread.items()), z):
        section, spec = SPREAD_FIELDS[name]
        values[name] = clip_to_range(getattr(sections[section], name) * (1.0 + s * zi), spec)
    drawn: dict[str, dict[str, Any]] = {'plant': {}, 'friction': {}}
    for k, v in values.items():
        drawn[SPREAD_FIELDS[k][0]][k] = v
    plant, friction = replace(base.plant, **drawn['plant']), replace(base.friction, **drawn['friction'])
    if (friction.mu_c > friction.mu_s) != (base.friction.mu_c > base.friction.mu_s):
        friction = replace(friction, mu_c=friction.mu_s)
    if 'mu_s' in spread or 'mu_c' in spread:      # the mu_c run (clipped or not): every row has the same keys
        values['mu_c'] = friction.mu_c
    return values, replace(base, plant=plant, friction=friction)


def run_chunk(chunk, duration: float) -> list[dict]:
    """Rows of runs (index, drawn values, scenario): the values, then the classification."""
    rows = []
    for index, values, scn in chunk:
        o, tr = classify_run(scn, duration)
        true_x, true_theta = true_p2p(o, tr)
        rows.append({'run': index, **values, 'class': o.cls, 'transition_time_s': o.transition_time,
                     'x_p2p_m': o.x_p2p, 'theta_p2p_rad': o.theta_p2p, 'true_x_p2p_m': true_x,
                     'true_theta_p2p_rad': true_theta, 'period_s': o.period_crossings})
    return rows


def run_montecarlo(draw: Callable[[int], tuple[dict, Scenario]], runs: int, duration: float,
                   workers: int | None = None, scheduler: str | None = None,
                   progress: Callable[[int, int], None] | None = None) -> list[dict]:
    """``runs`` runs of ``duration`` [s], run i with the parameters ``draw(i)``; rows in run order.

    In local processes (``workers``, default all cores) or on the Dask cluster at ``scheduler``.
    """
    runs_in = [(i, *draw(i)) for i in range(runs)]
    chunks = [runs_in[a:a + CHUNK] for a in range(0, runs, CHUNK)]
    rows: list[dict] = []
    with make_executor(scheduler, workers) as pool:
        for part in pool.map(run_chunk, chunks, [duration] * len(chunks)):
            rows += part
            if progress:
                progress(len(rows), runs)
    return rows


def _quantiles(values) -> dict | None:
    v = np.asarray([x for x in values if x is not None], float)
    if not len(v):
        return None
    return {f'q{round(100 * q):02d}': float(np.quantile(v, q)) for q in QUANTILES} | {
        'mean': float(v.mean()), 'std': float(v.std()), 'runs': len(v)}


def summarize(rows: list[dict]) -> dict:
    """Fraction of runs per class; quantiles (5, 25, 50, 75, 95 %), mean and std of the cart and angle
    peak-to-peak [m, rad] (measured and true) and of the period [s] over the hunting runs (``HUNTING``)."""
    n = len(rows)
    hunting = [r for r in rows if r['class'] in HUNTING]
    return {'runs': n,
            'fraction': {c: sum(r['class'] == c for r in rows) / n for c in CLASSES},
            'hunting_fraction': len(hunting) / n,
            **{k: _quantiles(r[k] for r in hunting) for k in RESULT_FIELDS[2:]}}


def write_results(rows: list[dict], info: dict, out: str | Path, title: str) -> dict:
    """``out/runs.csv`` (one row per run), ``out/summary.json`` (``info`` and :func:`summarize`) and
    ``out/histogram.png``; returns the summary."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / 'runs.csv', 'w', newline='') as fh:
        w = csv.DictWriter(fh, list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    summary = {**info, **summarize(rows), 'csv': str(out / 'runs.csv'), 'json': str(out / 'summary.json')}
    summary['figure'] = str(montecarlo_figure(rows, title, out / 'histogram.png'))
    (out / 'summary.json').write_text(json.dumps(summary, indent=2, default=float))
    return summary


#: the largest seed (run i draws with the seed (seed, i)); seeds are 0 .. MAX_SEED
MAX_SEED = 2**32 - 1
MAX_RUNS = 1_000_000     # --runs at most (1000 runs of 20 s take about 10 s on two cores: this is hours)
#: the fewest samples a run may take (--duration at least this many sample periods)
MIN_RUN_SAMPLES = 10


def check_seed(seed: int) -> int:
    """``--seed`` checked: a whole number in 0 .. :data:`MAX_SEED`."""
    if not 0 <= seed <= MAX_SEED:
        raise ConfigError(f'--seed: {seed} is out of range; allowed 0 .. {MAX_SEED} (run i draws with the '
                          f'seed (seed, i))')
    return seed


def check_duration(duration: float, base: Scenario) -> float:
    """``--duration`` [s] checked: finite, at least :data:`MIN_RUN_SAMPLES` samples of ``base``'s loop and
    at most the scenario schema's 1e6 s."""
    lo, hi = MIN_RUN_SAMPLES * base.sample_period, SIM_FIELDS['duration'].hi
    if not (math.isfinite(duration) and lo <= duration <= hi):
        raise ConfigError(f'--duration: {duration!r} s is out of range; allowed {lo:g} .. {hi:g} s (at least '
                          f'{MIN_RUN_SAMPLES} samples of {base.sample_period:g} s)')
    return duration


def spread_draws(base: Scenario, text: str, seed: int, distribution: str = 'normal'
                 ) -> tuple[Callable[[int], tuple[dict, Scenario]], dict]:
    """The draw of run i from relative spreads ``text`` ('mu_s=0.3,mu_c=0.3'), and what is drawn (for the
    summary)."""
    if distribution not in DISTRIBUTIONS:
        raise ConfigError(f'--distribution: {distribution!r} is not one of {", ".join(DISTRIBUTIONS)}')
    check_seed(seed)
    spread = parse_spread(text)
    meaning = ('value = nominal * (1 + s z), z ~ N(0, 1)' if distribution == 'normal' else
               'value = nominal * (1 + s u), u ~ U(-1, 1)')
    return (partial(spread_draw, base, spread, seed, distribution=distribution),
            {'spread': spread, 'distribution': distribution, 'meaning': meaning})


def montecarlo_study(draw: Callable[[int], tuple[dict, Scenario]], info: dict, runs: int, duration: float,
                     out: str | Path, title: str, workers: int | None = None, scheduler: str | None = None,
                     progress: Callable[[int, int], None] | None = None) -> dict:
    """:func:`run_montecarlo` of ``runs`` draws, written by :func:`write_results` into ``out`` (``info``
    heads the summary); returns the summary."""
    if not 1 <= runs <= MAX_RUNS:
        raise ConfigError(f'--runs: {runs} is out of range; allowed 1 .. {MAX_RUNS:,}')
    if not (math.isfinite(duration) and duration > 0):
        raise ConfigError(f'--duration: {duration!r} must be > 0 s')
    if workers is not None and workers < 1:
        raise ConfigError(f'--workers: {workers} must be >= 1')
    if scheduler:
        scheduler_address(scheduler)
    rows = run_montecarlo(draw, runs, duration, workers, scheduler, progress)
    return write_results(rows, {**info, 'runs': runs, 'duration_s': duration}, out, title)


def montecarlo_figure(rows, title: str, path: str | Path) -> Path:
    """Histograms of the cart and angle peak-to-peak and of the period over the hunting runs
    (:data:`HUNTING`; the true motion), with the share of every class in the title."""
    runs = [r for r in rows if r['class'] in HUNTING]
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    for ax, (key, scale, label) in zip(axes, (('true_x_p2p_m', 100.0, 'cart p2p (cm)'),
                                              ('true_theta_p2p_rad', 180.0 / math.pi, 'angle p2p (deg)'),
                                              ('period_s', 1.0, 'period (s)'))):
        v = [scale * r[key] for r in runs if r[key] is not None]
        if v:
            ax.hist(v, bins=min(40, max(5, len(v) // 10)), color='#fdae61', edgecolor='k', lw=0.3)
            ax.axvline(float(np.median(v)), color='k', ls=':', label=f'median {np.median(v):.3g}')
            ax.legend(fontsize=8)
        ax.set(xlabel=label, ylabel='runs')
    shares = ', '.join(f'{c.replace("_", " ")} {100 * sum(r["class"] == c for r in rows) / len(rows):.0f} %'
                       for c in CLASS_COLOURS if any(r['class'] == c for r in rows))
    fig.suptitle(f'{title}\n{len(rows)} runs: {shares}')
    return save_figure(fig, path)
