"""PNG figures of recorded runs, in the style of the paper's Figures 7-10, and what every figure shares
(the class colours, writing a figure)."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

#: colour of each class of :func:`ipfric_core.analysis.oscillation.classify`
CLASS_COLOURS = {'settled': '#2b8cbe', 'limit_cycle': '#fdae61', 'irregular': '#abdda4', 'growing': '#f46d43',
                 'fallen': '#d7191c'}


__all__ = ['CLASS_COLOURS', 'save_figure', 'run_figure', 'overlay_figure']

def save_figure(fig, path: str | Path) -> Path:
    """Write ``fig`` as a PNG (110 dpi) to ``path`` and close it; returns the path."""
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def run_figure(t, x, theta, voltage_t, voltage, title: str, path: str | Path, phase=None, spans=()) -> Path:
    """Cart position, angle and voltage against time (Figures 7-10), and the phase portrait.

    ``phase`` = (theta [rad], theta' [rad/s]) for the portrait, e.g. the ground truth; by
    default the encoder angle and its centred difference. ``spans``: (start [s], end [s],
    class) of regimes, shaded in the class colour behind the cart position.
    """
    fig, ax = plt.subplots(2, 2, figsize=(11, 6.5))
    for a, b, cls in spans:
        ax[0, 0].axvspan(a, b, color=CLASS_COLOURS[cls], alpha=0.3, lw=0, label=cls.replace('_', ' '))
    if spans:
        handles, labels = ax[0, 0].get_legend_handles_labels()
        unique = dict(zip(labels, handles))
        ax[0, 0].legend(unique.values(), unique.keys(), fontsize=7, loc='upper right')
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
    return save_figure(fig, path)


def overlay_figure(runs, labels, shifts, path: str | Path) -> Path:
    """Cart position of several runs; each shifted by (time [s], position [m]) as the
    paper shifts simulations onto experiments (the final cart position is arbitrary)."""
    fig, ax = plt.subplots(figsize=(9, 4))
    for (t, x), label, (dt, dx) in zip(runs, labels, shifts):
        ax.plot(np.asarray(t) + dt, np.asarray(x) + dx, lw=0.9, label=f'{label} (shift {dt:+.2f} s, {dx:+.4f} m)')
    ax.set(xlabel='time (sec)', ylabel='position (m)')
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return save_figure(fig, path)
