"""PNG figures of runs and sweeps, in the style of the paper's Figures 7-12."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

CLASS_COLOURS = {'settled': '#2b8cbe', 'limit_cycle': '#fdae61', 'growing': '#f46d43', 'fallen': '#d7191c'}


def run_figure(t, x, theta, voltage_t, voltage, title: str, path: str | Path, phase=None) -> Path:
    """Cart position, angle and voltage against time (Figures 7-10), and the phase portrait.

    ``phase`` = (theta [rad], theta' [rad/s]) for the portrait, e.g. the ground truth; by
    default the encoder angle and its centred difference.
    """
    fig, ax = plt.subplots(2, 2, figsize=(11, 6.5))
    ax[0, 0].plot(t, x, lw=0.8)
    ax[0, 0].set(xlabel='time (s)', ylabel='position (m)', title='cart position')
    ax[1, 0].plot(t, np.degrees(theta), lw=0.8, color='C1')
    ax[1, 0].set(xlabel='time (s)', ylabel='angle (deg)', title='pendulum angle')
    ax[0, 1].plot(voltage_t, voltage, lw=0.6, color='C2')
    ax[0, 1].set(xlabel='time (s)', ylabel='voltage (V)', title='command')
    if phase is not None:
        ax[1, 1].plot(np.degrees(phase[0]), np.degrees(phase[1]), lw=0.5, color='C3')
    elif len(t) > 2:
        ax[1, 1].plot(np.degrees(theta), np.degrees(np.gradient(theta, t)), lw=0.5, color='C3')
    ax[1, 1].set(xlabel='angle (deg)', ylabel='angular rate (deg/s)',
                 title='phase portrait' + (' (ground truth)' if phase is not None else ' (encoder)'))
    for a in ax.flat:
        a.grid(alpha=0.3)
    fig.suptitle(title)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def overlay_figure(runs, labels, shifts, path: str | Path) -> Path:
    """Cart position of several runs; each shifted by (time [s], position [m]) as the
    paper shifts simulations onto experiments (the final cart position is arbitrary)."""
    fig, ax = plt.subplots(figsize=(9, 4))
    for (t, x), label, (dt, dx) in zip(runs, labels, shifts):
        ax.plot(np.asarray(t) + dt, np.asarray(x) + dx, lw=0.9, label=f'{label} (shift {dt:+.2f} s, {dx:+.4f} m)')
    ax.set(xlabel='time (sec)', ylabel='position (m)')
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def stability_map(taus, thetas_deg, classes, title: str, path: str | Path) -> Path:
    """Regions stable / oscillations / falls in the (tau, theta0) plane (Figures 11-12)."""
    names = list(CLASS_COLOURS)
    grid = np.array([[names.index(c) for c in row] for row in classes], float)
    fig, ax = plt.subplots(figsize=(8, 5))
    cmap = matplotlib.colors.ListedColormap([CLASS_COLOURS[n] for n in names])
    dtau = (taus[1] - taus[0]) if len(taus) > 1 else 0.005
    dth = (thetas_deg[1] - thetas_deg[0]) if len(thetas_deg) > 1 else 0.5
    ax.imshow(grid, origin='lower', aspect='auto', cmap=cmap, vmin=-0.5, vmax=len(names) - 0.5,
              extent=(taus[0] - dtau / 2, taus[-1] + dtau / 2, thetas_deg[0] - dth / 2, thetas_deg[-1] + dth / 2),
              interpolation='nearest')
    handles = [matplotlib.patches.Patch(color=CLASS_COLOURS[n], label=n.replace('_', ' ')) for n in names]
    ax.legend(handles=handles, loc='upper right', fontsize=8)
    ax.set(xlabel='τ (sec)', ylabel='θ0 (deg)', title=title)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
