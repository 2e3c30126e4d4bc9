"""Report of a ladder identification: result.json, report.md and PNG figures in one directory."""
from __future__ import annotations

import json
import math
from pathlib import Path

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .ladder import TYPICAL, Problem, Step  # noqa: E402
from .report import save_figure, write_report  # noqa: E402


def param_table(step: Step) -> list[dict]:
    """Every parameter of a step: value, standard error (fitted ones), unit, fitted or known."""
    return [{'name': p.name, 'value': p.value, 'std': step.std.get(p.name), 'unit': p.unit,
             'fitted': p.free, 'at_bound': p.at_bound(1e-3 * TYPICAL.get(p.name, 1.0)), 'doc': p.doc}
            for p in step.model.params]


def identified(step: Step, dt: float) -> dict:
    """The model of a step as a scenario's sections: plant, friction (coefficients of its own
    normal force), plant_truth (every effect parameter, cogging phase included)."""
    m = step.model
    plant = m.plant_params()
    return {'plant': {k: getattr(plant, k) for k in ('M', 'm', 'l', 'g', 'alpha', 'beta')},
            'friction': m.friction_params().to_dict(), 'normal_force_N': m.normal_force,
            'plant_truth': {k: v for k, v in m.plant_truth(dt).to_dict().items() if v and not k.startswith('noise')}}


def ladder_result(res: dict) -> dict:
    est, val = res['estimation'], res['validation']
    steps = res['steps']
    return {
        'data': {'estimation': est.name, 'validation': val.name, 'samples': [len(est.t), len(val.t)],
                 'sample_period_s': est.dt, 'pendulum': est.theta is not None,
                 'encoder_counts': {'x_m': est.x_resolution,
                                    'theta_rad': est.theta_resolution if est.theta is not None else None},
                 'notes': list(dict.fromkeys(est.notes + val.notes))},
        'metric': 'simulation error by multiple shooting, in encoder counts (RMS) and in % of the motion '
                  'within the windows; estimation data fit, validation data judge',
        'ladder': [{'step': s.label, 'effects': list(s.model.effects), 'estimation': s.est, 'validation': s.val,
                    'params': param_table(s), 'notes': s.notes} for s in steps],
        'effects_added': list(steps[-1].model.effects),
        'effects_tried': res['tried'],
        'identified': identified(steps[-1], est.dt),
    }


def _fmt(p: dict) -> str:
    std = '' if p['std'] is None or not math.isfinite(p['std']) else f' +/- {p["std"]:.2g}'
    return f'{p["value"]:.5g}{std}'


def ladder_markdown(r: dict) -> str:
    d = r['data']
    lines = [f'# Identification: {d["estimation"]}', '',
             f'Metric: {r["metric"]}. Encoder counts: cart {d["encoder_counts"]["x_m"]:.4g} m'
             + (f', angle {d["encoder_counts"]["theta_rad"]:.4g} rad' if d['pendulum'] else '') + '.', '']
    if d['notes']:
        lines += ['Data: ' + '; '.join(d['notes']) + '.', '']
    lines += ['## The ladder', '',
              '| step | estimation x (counts) | validation x (counts) | validation x (%) | validation theta (counts) |',
              '| --- | --- | --- | --- | --- |']
    for s in r['ladder']:
        e, v = s['estimation'], s['validation']
        th = f'{v["theta_rms_counts"]:.3g}' if 'theta_rms_counts' in v else '-'
        lines.append(f'| {s["step"]} | {e["x_rms_counts"]:.3g} | {v["x_rms_counts"]:.3g} | {v["x_percent"]:.3g} '
                     f'| {th} |')
    lines += ['', f'Effects added: {", ".join(r["effects_added"]) or "none"}.', '']
    for s in r['ladder']:
        lines += [f'### {s["step"]}', '', '| parameter | value | unit | fitted | |', '| --- | --- | --- | --- | --- |']
        for p in s['params']:
            flag = 'on a bound' if p['at_bound'] else ''
            lines.append(f'| {p["name"]} | {_fmt(p)} | {p["unit"]} | {"yes" if p["fitted"] else "known"} | {flag} |')
        lines += [''] + [f'- {n}' for n in s['notes']] + ([''] if s['notes'] else [])
    lines += ['## Effects tried', '', '| effect | validation gain % | p | kept | why not |',
              '| --- | --- | --- | --- | --- |']
    for t in r['effects_tried']:
        why = '; '.join(t['refused']).replace('|', '/')
        lines.append(f'| {t["effect"]} | {t["validation_gain_percent"]:.2f} | {t["p_value"]:.2g} | {t["kept"]} '
                     f'| {why} |')
    idf = r['identified']
    lines += ['', '## Identified model (scenario sections)', '', '```yaml',
              f'plant: {json.dumps(idf["plant"])}', f'friction: {json.dumps(idf["friction"])}',
              f'plant_truth: {json.dumps(idf["plant_truth"])}', '```', '',
              'Figures: ladder.png (error at each step), windows.png (measured and simulated cart position '
              'on validation windows, declared and final model).', '']
    return '\n'.join(lines)


def ladder_figures(res: dict, out: Path) -> list[str]:
    steps = res['steps']
    files = []
    fig, ax = plt.subplots(figsize=(7, 4))
    labels = [s.label for s in steps]
    xs = np.arange(len(steps))
    ax.bar(xs - 0.2, [s.est['x_rms_counts'] for s in steps], 0.4, label='estimation')
    ax.bar(xs + 0.2, [s.val['x_rms_counts'] for s in steps], 0.4, label='validation')
    ax.set_xticks(xs, labels)
    ax.set_yscale('log')
    ax.set(ylabel='cart simulation error (RMS counts)', title='the ladder')
    ax.legend()
    files.append(save_figure(fig, out / 'ladder.png'))
    pv = Problem(res['validation'])
    rec = pv.rec
    win = pv.blocks[0][1]
    first, last = pv.predictions(steps[0].model)[0], pv.predictions(steps[-1].model)[0]
    n = min(len(win), 6)
    pick = np.linspace(0, len(win) - 1, n).astype(int)
    fig, axes = plt.subplots(n, 1, figsize=(9, 1.6 * n + 1), squeeze=False)
    for ax, i in zip(axes[:, 0], pick):
        a, b = win.start[i], win.stop[i]
        t = rec.t[a:b]
        ax.plot(t, rec.x[a:b] * 1e3, 'k.', ms=2, label='measured')
        ax.plot(t, first.x[a:b] * 1e3, lw=1, label=steps[0].label)
        ax.plot(t, last.x[a:b] * 1e3, lw=1, label=steps[-1].label)
        ax.set_ylabel('x (mm)')
    axes[0, 0].legend(fontsize=7)
    axes[-1, 0].set_xlabel('time (s)')
    fig.suptitle('validation windows: measured and simulated cart position')
    files.append(save_figure(fig, out / 'windows.png'))
    return files


def write_ladder_report(res: dict, out: str | Path, plots: bool = True) -> dict:
    """Write result.json, report.md and the figures of a ladder into ``out``; the result dict."""
    return write_report(res, out, plots, ladder_result, ladder_figures, ladder_markdown)
