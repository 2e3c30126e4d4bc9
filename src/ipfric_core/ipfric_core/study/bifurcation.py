"""The bifurcation diagram of the closed loop: branches of periodic orbits over a parameter,
overlaid on what simulations from the scenario's start do at the same parameters.

Stable orbits are drawn solid, unstable dashed; each simulation is a marker coloured by its
class (:func:`ipfric_core.study.outcome.classify_run`) at its cart amplitude; for the
delay, the linear critical delays tau_c (eq. 27, tanh-smoothed friction and sliding cart) are marked.
"""
from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from ..analysis.plots import CLASS_COLOURS, save_figure
from .check import linear_delays
from .outcome import classify_run
from .variants import scenario_at

__all__ = ['diagram']


def simulated_classes(base, name: str, values, duration: float = 20.0) -> list[dict]:
    """Class and cart amplitude of a run from the scenario's start at each parameter value."""
    rows = []
    for v in values:
        scn = scenario_at(base, name, v)
        o, _ = classify_run(scn, duration)
        rows.append({'parameter': v, 'class': o.cls, 'x_p2p_m': o.x_p2p})
    return rows


def diagram(base, name: str, values, rows: list[dict], events: list[dict], path: str | Path,
            describing=None) -> Path:
    """Draw the diagram to ``path`` (PNG); ``describing``: optional rows (parameter, x_p2p_m)."""
    fig, ax = plt.subplots(figsize=(8, 4.8))
    for b in sorted({r['branch'] for r in rows}):
        pts = [r for r in rows if r['branch'] == b]
        p = np.array([r['parameter'] for r in pts])
        x = 100 * np.array([r['x_p2p_m'] for r in pts])
        stable = np.array([r['stable'] for r in pts])
        for flag, style in ((True, '-'), (False, '--')):
            y = np.where(stable == flag, x, np.nan)
            ax.plot(p, y, style, color='tab:blue' if flag else 'tab:purple', lw=1.8, marker='x', ms=5,
                    label=('stable orbit' if flag else 'unstable orbit') if b == 0 else None)
    sims = simulated_classes(base, name, values)
    for cls, colour in CLASS_COLOURS.items():
        sel = [s for s in sims if s['class'] == cls]
        if sel:
            ax.scatter([s['parameter'] for s in sel], [100 * s['x_p2p_m'] for s in sel], s=14, color=colour,
                       marker='o', alpha=0.6, label=f'simulation: {cls.replace("_", " ")}', zorder=3)
    if describing:
        ax.plot([d['parameter'] for d in describing], [100 * d['x_p2p_m'] for d in describing], ':',
                color='tab:gray', lw=1.5, label='describing function')
    for e in events:
        if e['event'] == 'fold':
            ax.axvline(e['parameter'], color='tab:purple', lw=0.6, ls=':')
    if name == 'delay':
        tau = linear_delays(base.plant, base.friction, base.gain())
        for kind, style, what in (('tanh', '-.', 'tanh-smoothed friction'), ('sliding', '--', 'sliding cart')):
            tau_c = tau[kind]['tau_c']
            if math.isfinite(tau_c) and 0 < tau_c and min(values) <= tau_c <= max(values):
                ax.axvline(tau_c, color='tab:red', lw=1, ls=style, label=f'linear tau_c, {what}: {1e3 * tau_c:.1f} ms')
    ax.set_xlabel({'delay': 'feedback delay tau [s]', 'gain': 'gain scale', 'friction': 'friction scale'}[name])
    ax.set_ylabel('cart peak-to-peak [cm]')
    ax.set_yscale('log')
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc='best')
    ax.set_title('periodic orbits of the sampled loop (lines) and simulations from the start (dots)', fontsize=9)
    return save_figure(fig, path)
