"""PNG figures of runs and sweeps, in the style of the paper's Figures 7-12."""
from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..constants import ANGLE_RESOLUTION_RAD  # noqa: E402

CLASS_COLOURS = {'settled': '#2b8cbe', 'limit_cycle': '#fdae61', 'irregular': '#abdda4', 'growing': '#f46d43',
                 'fallen': '#d7191c'}


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


def _draw_map(ax, taus, thetas_deg, classes, title: str) -> None:
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


def _save(fig, path) -> Path:
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def stability_map(taus, thetas_deg, classes, title: str, path: str | Path) -> Path:
    """Regions stable / oscillations / falls in the (tau, theta0) plane (Figures 11-12)."""
    fig, ax = plt.subplots(figsize=(8, 5))
    _draw_map(ax, taus, thetas_deg, classes, title)
    return _save(fig, path)


def transition_figure(panels, title: str, path: str | Path) -> Path:
    """The paper's Figures 11-12: panels (full range, zoom) of transition delays against theta0.

    ``panels``: list of dicts with ``title``, ``taus``, ``thetas_deg``, ``classes`` (the map
    drawn underneath, of the first variant) and ``curves``: (label, linestyle, thetas_deg,
    first unsettled tau, first fallen tau) per variant; each line is drawn half a grid step
    before those delays, between the classes, like the paper's lines.
    """
    fig, axes = plt.subplots(len(panels), 1, figsize=(8, 4.2 * len(panels)))
    for ax, p in zip(np.atleast_1d(axes), panels):
        _draw_map(ax, p['taus'], p['thetas_deg'], p['classes'], p['title'])
        half = 0.5 * (p['taus'][1] - p['taus'][0])
        for label, style, ths, unsettled, fallen in p['curves']:
            lo = [np.nan if v is None else v - half for v in unsettled]
            hi = [np.nan if v is None else v - half for v in fallen]
            ax.plot(lo, ths, color='k', ls=style, lw=1.6, label=f'{label}: loss of stability')
            ax.plot(hi, ths, color='#4a1486', ls=style, lw=1.6, label=f'{label}: falls')
        ax.legend(loc='upper right', fontsize=7)
    fig.suptitle(title)
    return _save(fig, path)


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
    return _save(fig, path)


def montecarlo_figure(rows, hunting, title: str, path: str | Path) -> Path:
    """Histograms of the cart and angle peak-to-peak and of the period over the runs whose class is
    in ``hunting`` (the true motion), with the share of every class in the title."""
    runs = [r for r in rows if r['class'] in hunting]
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
    return _save(fig, path)


def check_figure(result: dict, path: str | Path) -> Path:
    """The design check's figure (``design.check.design_check``): cart peak-to-peak and period of
    the hunting against the friction cases (orbit with exact sensors, the encoders' cycle, the
    describing function, the encoder floor), and the runs of the delay scan of the nominal case
    with the linear and effective critical delays."""
    cases = result['cases']
    v = [c['value'] for c in cases]
    fig, (a1, a2, a3) = plt.subplots(1, 3, figsize=(14, 4.2))

    def line(ax, key, factor, style, label, colour):
        y = [np.nan if c['numbers'][key] is None else factor * c['numbers'][key] for c in cases]
        ax.plot(v, y, style, color=colour, label=label)
    line(a1, 'x_p2p_exact_m', 100.0, 'o-', 'exact sensors (orbit; 0: rests)', 'tab:blue')
    line(a1, 'x_p2p_encoders_m', 100.0, 's-', 'encoders', 'tab:orange')
    line(a1, 'x_p2p_describing_m', 100.0, 'd:', 'describing function', 'tab:gray')
    line(a1, 'floor_x_p2p_m', 100.0, 'v--', 'encoder floor (viscous only)', 'tab:green')
    a1.set(xlabel=result['axis'], ylabel='cart peak-to-peak (cm)', title='hunting amplitude')
    line(a2, 'period_exact_s', 1.0, 'o-', 'exact sensors (orbit)', 'tab:blue')
    line(a2, 'period_encoders_s', 1.0, 's-', 'encoders', 'tab:orange')
    line(a2, 'period_describing_s', 1.0, 'd:', 'describing function', 'tab:gray')
    a2.set(xlabel=result['axis'], ylabel='period (s)', title='hunting period')
    nominal = cases[result['nominal']]
    for kind, colour in (('exact', 'tab:blue'), ('encoders', 'tab:orange')):
        e = nominal['effective_delay'][kind]
        held = [r for r in e['scan'] if r['holds']]
        lost = [r for r in e['scan'] if not r['holds']]
        a3.plot([1e3 * r['delay_s'] for r in held], [100 * max(r['x_p2p_m'], 1e-4) for r in held], 'o-', ms=3,
                color=colour, label=f'runs, {"exact sensors" if kind == "exact" else "encoders"}')
        if lost:
            a3.plot([1e3 * r['delay_s'] for r in lost], [40.0] * len(lost), 'x', color=colour, ms=5)
        if e['holds_to_s'] is not None:
            a3.axvline(1e3 * e['holds_to_s'], color=colour, ls='--', lw=1,
                       label=f'holds to {1e3 * e["holds_to_s"]:.1f} ms ({kind})')
    tau = nominal['linear_critical_delay']['sliding']['tau_c']
    if tau is not None:
        a3.axvline(1e3 * tau, color='tab:red', ls='-.', lw=1, label=f'linear tau_c (sliding) {1e3 * tau:.1f} ms')
    a3.set_yscale('log')
    a3.set(xlabel='feedback delay (ms)', ylabel='cart peak-to-peak (cm); rest at 0.01, x: lost',
           title=f'{nominal["label"]}: runs of {nominal["effective_delay"]["exact"]["run_s"]:g} s from the start')
    for ax in (a1, a2, a3):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f'design check: {result["scenario"]}, gain ' + ', '.join(f'{k:.4g}' for k in result['gain']))
    return _save(fig, path)
