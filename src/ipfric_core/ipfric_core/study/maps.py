"""PNG figures of the sweeps: stability maps over tau and theta0 (Figures 11-12) and the
oscillation against encoder resolution (section 6)."""
from __future__ import annotations

import math
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

from ..analysis.plots import CLASS_COLOURS, save_figure
from ..constants import ANGLE_RESOLUTION_RAD

__all__ = ['stability_map', 'transition_figure', 'resolution_figure']


def draw_map(ax, taus, thetas_deg, classes, title: str) -> None:
    names = list(CLASS_COLOURS)
    grid = np.array([[names.index(c) for c in row] for row in classes], float)
    cmap = matplotlib.colors.ListedColormap([CLASS_COLOURS[n] for n in names])
    dtau = (taus[1] - taus[0]) if len(taus) > 1 else 0.005
    dth = (thetas_deg[1] - thetas_deg[0]) if len(thetas_deg) > 1 else 0.5
    ax.imshow(grid, origin='lower', aspect='auto', cmap=cmap, vmin=-0.5, vmax=len(names) - 0.5,
              extent=(taus[0] - dtau / 2, taus[-1] + dtau / 2, thetas_deg[0] - dth / 2, thetas_deg[-1] + dth / 2),
              interpolation='nearest')
    handles = [matplotlib.patches.Patch(color=CLASS_COLOURS[n], label=n.replace('_', ' ')) for n in names]
    ax.legend(handles=handles, loc='upper right', fontsize=8)
    ax.set(xlabel='τ (sec)', ylabel='θ0 (deg)', title=title)


def stability_map(taus, thetas_deg, classes, title: str, path: str | Path) -> Path:
    """Regions stable / oscillations / falls in the (tau, theta0) plane (Figures 11-12)."""
    fig, ax = plt.subplots(figsize=(8, 5))
    draw_map(ax, taus, thetas_deg, classes, title)
    return save_figure(fig, path)


def transition_figure(panels, title: str, path: str | Path) -> Path:
    """The paper's Figures 11-12: panels (full range, zoom) of transition delays against theta0.

    ``panels``: list of dicts with ``title``, ``taus``, ``thetas_deg``, ``classes`` (the map
    drawn underneath, of the first variant) and ``curves``: (label, linestyle, thetas_deg,
    first unsettled tau, first fallen tau) per variant; each line is drawn half a grid step
    before those delays, between the classes, like the paper's lines.
    """
    fig, axes = plt.subplots(len(panels), 1, figsize=(8, 4.2 * len(panels)))
    for ax, p in zip(np.atleast_1d(axes), panels):
        draw_map(ax, p['taus'], p['thetas_deg'], p['classes'], p['title'])
        half = 0.5 * (p['taus'][1] - p['taus'][0])
        for label, style, ths, unsettled, fallen in p['curves']:
            lo = [np.nan if v is None else v - half for v in unsettled]
            hi = [np.nan if v is None else v - half for v in fallen]
            ax.plot(lo, ths, color='k', ls=style, lw=1.6, label=f'{label}: loss of stability')
            ax.plot(hi, ths, color='#4a1486', ls=style, lw=1.6, label=f'{label}: falls')
        ax.legend(loc='upper right', fontsize=7)
    fig.suptitle(title)
    return save_figure(fig, path)


def resolution_figure(rows, title: str, path: str | Path) -> Path:
    """Peak-to-peak of the true cart position and angle against the encoder resolution (section 6)."""
    ang = np.degrees([r['angle_resolution_rad'] for r in rows])
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    a1.plot(ang, [1e3 * r['true_x_p2p_m'] for r in rows], 'o-')
    a1.set(xlabel='angle encoder count (deg)', ylabel='cart p2p (mm)')
    a2.plot(ang, np.degrees([r['true_theta_p2p_rad'] for r in rows]), 'o-', color='C1')
    a2.set(xlabel='angle encoder count (deg)', ylabel='angle p2p (deg)')
    for ax in (a1, a2):
        ax.axvline(math.degrees(ANGLE_RESOLUTION_RAD), color='grey', ls=':', label="the paper's rig")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(title)
    return save_figure(fig, path)
