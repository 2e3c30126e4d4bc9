"""Report of an identification: result.json, report.md and PNG figures in one directory."""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..analysis.plots import save_figure  # noqa: E402
from ..analysis.records import smooth_rate  # noqa: E402
from ..physics.friction import sliding_friction  # noqa: E402
from . import shooting  # noqa: E402
from .effects import BASE_MODELS, PARAMS, static_level  # noqa: E402
from .hypotheses import CORRECTABLE  # noqa: E402
from .ladder import Step  # noqa: E402
from .problem import Problem  # noqa: E402

__all__ = ['correlation_lines', 'write_ladder_report']

CORRELATED = 0.9     # pairs of fitted parameters correlated at least this much are reported
CHI2_2D_95 = 5.991   # chi-square quantile of a 95 % joint region of two parameters


def param_table(step: Step) -> list[dict]:
    """Every parameter of a step: value, standard error (fitted ones), unit, fitted or known, and
    whether its error comes from a scan along it, the simulated error being rough in it (``rough``) or
    flatter than a quadratic on a side (``flat``), and whether the scan stayed low up to a bound
    (``unconfined``: 'lo', 'hi' or 'both')."""
    rough, flat = getattr(step.std, 'rough', ()), getattr(step.std, 'flat', ())
    reach = getattr(step.std, 'reach', {})
    return [{'name': p.name, 'value': p.value, 'std': step.std.get(p.name), 'unit': p.unit,
             'fitted': p.free, 'at_bound': p.at_bound(1e-3 * PARAMS[p.name].typical), 'doc': p.doc,
             'rough': p.name in rough, 'flat': p.name in flat, 'unconfined': reach.get(p.name, '')}
            for p in step.model.params]


def correlations(step: Step, threshold: float = CORRELATED) -> list[dict]:
    """The pairs of fitted parameters of a step whose estimates are correlated at least ``threshold``:
    the correlation, the combination a + w b the data determine best (w = -cov(a, b) / var(b), its
    value and standard error; for the Coulomb level and the viscous slope, w is the speed [m/s] at
    which the data fix the sliding friction) and the 95 % joint confidence region of the pair (an
    ellipse; its extent along each parameter)."""
    errors: Any = step.std
    if not hasattr(errors, 'correlations'):
        return []
    index = {n: i for i, n in enumerate(errors.names)}
    out = []
    for a, b, r in errors.correlations(threshold):
        i, j = index[a], index[b]
        va, vb, cab = errors.cov[i, i], errors.cov[j, j], errors.cov[i, j]
        w = -cab / vb
        half_a, half_b = math.sqrt(CHI2_2D_95 * va), math.sqrt(CHI2_2D_95 * vb)
        ma, mb = step.model[a], step.model[b]
        out.append({'a': a, 'b': b, 'r': r, 'weight': w, 'combination': ma + w * mb,
                    'combination_std': math.sqrt(max(va - cab ** 2 / vb, 0.0)),
                    'region_95': {a: [ma - half_a, ma + half_a], b: [mb - half_b, mb + half_b]}})
    return out


def covariance(step: Step) -> dict | None:
    """The covariance of the step's fitted parameters (physical units), or None."""
    errors: Any = step.std
    if not hasattr(errors, 'cov'):
        return None
    return {'names': list(errors.names), 'matrix': [[float(v) for v in row] for row in errors.cov]}


def correlation_lines(s: dict, units: dict) -> list[str]:
    """One sentence per correlated pair of a step of result.json (:func:`correlations`), and one with
    the friction at the speeds the cart moved at (:func:`friction_curve`) when there are such pairs."""
    lines = []
    curve = s.get('friction_at_speeds') or []
    if s.get('correlations') and curve:
        lines.append('sliding friction at the speeds the cart moved at (5th, 50th, 95th percentile): ' + ', '.join(
            f'{c["force"]:.4g} +/- {c["std"]:.2g} N at {c["v"]:.3g} m/s' for c in curve))
    for c in s.get('correlations', []):
        a, b = c['a'], c['b']
        (a0, a1), (b0, b1) = c['region_95'][a], c['region_95'][b]
        lines.append(f'{a} and {b} are correlated (r = {c["r"]:+.3f}): the data determine {a} '
                     f'{c["weight"]:+.4g} {b} = {c["combination"]:.4g} +/- {c["combination_std"]:.2g} {units[a]}; '
                     f'along it they trade (95 % joint region: {a} {a0:.4g} .. {a1:.4g} {units[a]}, '
                     f'{b} {b0:.4g} .. {b1:.4g} {units[b]})')
    return lines


def identified(step: Step, dt: float) -> dict:
    """The model of a step as a scenario's sections: plant, friction (coefficients of its own
    normal force), plant_truth (every effect parameter, cogging phase included)."""
    m = step.model
    plant = m.plant_params()
    truth = {k: v for k, v in m.plant_truth(dt).to_dict().items() if v and not k.startswith('noise')}
    if not (truth.get('cogging_sin_N') or truth.get('cogging_cos_N')):
        truth.pop('cogging_period_m', None)     # the period of no cogging: a default, not a finding
    return {'plant': {k: getattr(plant, k) for k in ('M', 'm', 'l', 'g', 'alpha', 'beta')},
            'friction': m.friction_params().to_dict(), 'normal_force_N': m.normal_force, 'plant_truth': truth}


MOVING = 0.005       # a speed above this moves the cart [m/s] (the speeds reported: of those samples)


def speeds(rec) -> dict:
    """5th, 50th and 95th percentile of the cart's speed [m/s] over the samples where it moves."""
    v = np.abs(smooth_rate(rec.t, rec.x, rec.valid_mask, shooting.FILTER_HZ))
    v = v[v > MOVING]
    if len(v) == 0:
        return {}
    return {f'p{q}': float(np.quantile(v, q / 100)) for q in (5, 50, 95)}


def friction_curve(step: Step, at: dict) -> list[dict]:
    """The steady sliding friction [N] of the step's model (moving forward) at the speeds ``at`` (:func:`speeds`)
    with its standard error from the covariance of the fitted parameters (first order): where the
    cart never moves fast, these are what the data determine, not the law's parameters one by one."""
    errors: Any = step.std
    if not hasattr(errors, 'cov') or not at:
        return []
    names = [n for n in errors.names if n in ('Fc', 'Fs_excess', 'eps', 'v_s', 'asymmetry',
                                                 'asymmetry_viscous_Ns_per_m')]
    if not names:
        return []
    index = [errors.names.index(n) for n in names]
    cov = errors.cov[np.ix_(index, index)]

    def force(model, v):
        return -float(sliding_friction(model.vectors().fp, v))
    out = []
    for key, v in at.items():
        f0 = force(step.model, v)
        grad = []
        for n in names:
            h = 1e-6 * max(abs(step.model[n]), PARAMS[n].typical)
            grad.append((force(step.model.with_values({n: step.model[n] + h}), v) - f0) / h)
        g = np.array(grad)
        out.append({'speed': key, 'v': v, 'force': f0, 'std': float(math.sqrt(max(g @ cov @ g, 0.0)))})
    return out


def coverage_note(step: Step, at: dict) -> list[str]:
    """Why the law's parameters are not separately determined where the cart never reaches its
    Stribeck velocity (the speeds covered: :func:`speeds`)."""
    if (not hasattr(step.std, 'cov') or 'v_s' not in step.std or not at
            or at['p95'] >= step.model['v_s']):
        return []
    return [f'the cart moved at {at["p5"]:.3g} to {at["p95"]:.3g} m/s (5th to 95th percentile of the moving '
            f'samples), below the Stribeck velocity v_s = {step.model["v_s"]:.3g} m/s: the data determine the '
            f'friction at those speeds, not the Coulomb level beyond v_s nor the viscous slope apart']


def curve_note(step: Step) -> list[str]:
    """What a Stribeck curve that rises with speed (a static level below the Coulomb level) says."""
    m = step.model
    if 'stribeck' not in BASE_MODELS[m.law] or m['Fs_excess'] >= 0.0:
        return []
    return [f'the friction rises with speed: from a static level of {static_level(m["Fc"], m["Fs_excess"]):.4g} N '
            f'at rest to the Coulomb level {m["Fc"]:.4g} N beyond v_s = {m["v_s"]:.3g} m/s (eq. 8 with Fs below Fc)']


def ladder_result(res: dict) -> dict:
    est, val = res['estimation'], res['validation']
    steps = res['steps']
    at = speeds(est)
    return {
        'data': {'estimation': est.name, 'validation': val.name, 'samples': [len(est.t), len(val.t)],
                 'sample_period_s': est.dt, 'pendulum': est.theta is not None,
                 'encoder_counts': {'x_m': est.x_resolution,
                                    'theta_rad': est.theta_resolution if est.theta is not None else None},
                 'moving_speeds_mps': at,
                 'notes': list(dict.fromkeys(est.notes + val.notes))},
        'metric': 'simulation error by multiple shooting, in encoder counts (RMS) and in % of the motion '
                  'within the windows; estimation data fit, validation data judge',
        'ladder': [{'step': s.label, 'effects': list(s.model.effects), 'estimation': s.est, 'validation': s.val,
                    'params': param_table(s), 'correlations': correlations(s), 'covariance': covariance(s),
                    'friction_at_speeds': friction_curve(s, at),
                    'notes': s.notes + coverage_note(s, at) + curve_note(s)}
                   for s in steps],
        'effects_added': list(steps[-1].model.effects),
        'constants_corrected': [n for n in CORRECTABLE if steps[-1].model.param(n).free],
        'verdict': res['verdict'],
        'rounds': res['rounds'],
        'effects_tried': res['tried'],
        'identified': identified(steps[-1], est.dt),
        **({'force_error': res['force_error']} if 'force_error' in res else {}),
        **({'test': {k: v for k, v in res['test'].items() if k not in ('t', 'simulated', 'measured')}}
           if 'test' in res else {}),
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
    v = r['verdict']
    lines += ['', f'Effects added: {", ".join(r["effects_added"]) or "none"}; constants corrected: '
              f'{", ".join(r["constants_corrected"]) or "none"}.', '', f'**Verdict**: {v["reason"]}.', '']
    if not v['explained']:
        lines += ['Tried: ' + ', '.join(v.get('tried', [])) + '.', '',
                  'The largest signatures left (the hypotheses of the last round that lowered the validation '
                  'error most, and why each was refused):', '']
        lines += [f'- {t["hypothesis"]}: {t["validation_gain_percent"]:.3g} % ({"; ".join(t["refused"])})'
                  for t in v.get('largest_left', [])] + ['']
    lines += ['Rounds (the explanation kept, and the runner-up with its validation error):', '']
    for rd in r['rounds']:
        ru = rd['runner_up']
        lines.append(f'- round {rd["round"]}: kept {rd["kept"] or "nothing"}'
                     + (f'; runner-up {ru["hypothesis"]} ({ru["validation_x_rms_counts"]:.3g} counts)' if ru else ''))
    lines.append('')
    for s in r['ladder']:
        lines += [f'### {s["step"]}', '', '| parameter | value | unit | fitted | |', '| --- | --- | --- | --- | --- |']
        for p in s['params']:
            flag = '; '.join(f for f in ('on a bound' if p['at_bound'] else '',
                                         'rough: error from a scan' if p.get('rough') else '',
                                         'flat profile: error from a scan' if p.get('flat') else '',
                                         f'not confined ({p["unconfined"]})' if p.get('unconfined') else '') if f)
            lines.append(f'| {p["name"]} | {_fmt(p)} | {p["unit"]} | {"yes" if p["fitted"] else "known"} | {flag} |')
        units = {p['name']: p['unit'] for p in s['params']}
        notes = s['notes'] + correlation_lines(s, units)
        lines += [''] + [f'- {n}' for n in notes] + ([''] if notes else [])
    lines += ['## Hypotheses tried', '', '| round | hypothesis | validation gain % | p | kept | why not |',
              '| --- | --- | --- | --- | --- | --- |']
    for t in r['effects_tried']:
        why = '; '.join(t['refused']).replace('|', '/')
        lines.append(f'| {t["round"]} | {t["hypothesis"]} | {t["validation_gain_percent"]:.2f} | {t["p_value"]:.2g} '
                     f'| {t["kept"]} | {why} |')
    if 'force_error' in r:
        lines += ['', '## Force error', '', 'Relative force error 100 ||F - F_model|| / ||F|| of each step\'s force '
                  'balance (filtered, decimated; the EMPS benchmark\'s metric):', '',
                  '| step | estimation % | validation % |', '| --- | --- | --- |']
        lines += [f'| {f["step"]} | {f["estimation"]["relative_percent"]:.3f} | '
                  f'{f["validation"]["relative_percent"]:.3f} |' for f in r['force_error']]
    if 'test' in r:
        t = r['test']
        lines += ['', '## Test record run free', '', f'The final model run free over {t["record"]} from its first '
                  f'{t["init_samples"]} readings: position RMS error {t["rmse_mm"]:.4g} mm '
                  f'({t["rmse_counts"]:.4g} counts) over {t["samples"]} readings, a travel of '
                  f'{t["travel_mm"]:.4g} mm (figure test.png).']
    idf = r['identified']
    lines += ['', '## Identified model (scenario sections)', '', '```yaml',
              f'plant: {json.dumps(idf["plant"])}', f'friction: {json.dumps(idf["friction"])}',
              f'plant_truth: {json.dumps(idf["plant_truth"])}', '```', '']
    what = {'ladder.png': 'the error at each step', 'windows.png': 'measured and simulated cart position on '
            'validation windows, declared and final model', 'test.png': 'the final model run free over the test record'}
    if r.get('figures'):
        names = [Path(f).name for f in r['figures']]
        lines += ['Figures: ' + ', '.join(f'{n} ({what[n]})' if n in what else n for n in names) + '.', '']
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
    if 'test' in res:
        t = res['test']
        fig, ax = plt.subplots(2, 1, figsize=(9, 5), sharex=True)
        ax[0].plot(t['t'], t['measured'] * 1e3, 'k', lw=1, label='measured')
        ax[0].plot(t['t'], t['simulated'] * 1e3, lw=1, label=f'{steps[-1].label}, run free')
        ax[0].set(ylabel='x (mm)', title=f'{t["record"]}: the final model run free from {t["init_samples"]} readings')
        ax[0].legend(fontsize=7)
        ax[1].plot(t['t'], (t['simulated'] - t['measured']) * 1e3, lw=0.8)
        ax[1].set(xlabel='time (s)', ylabel='error (mm)')
        files.append(save_figure(fig, out / 'test.png'))
    return [str(f) for f in files]


def write_ladder_report(res: dict, out: str | Path, plots: bool = True) -> dict:
    """Write result.json, report.md and the figures of a ladder (:func:`ladder.run_ladder`'s result) into
    ``out``; the result dict (result.json's content)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    r = ladder_result(res)
    r['figures'] = ladder_figures(res, out) if plots else []
    r['files'] = {'report': str(out / 'report.md'), 'result': str(out / 'result.json')}
    (out / 'result.json').write_text(json.dumps(r, indent=2, default=float))
    (out / 'report.md').write_text(ladder_markdown(r))
    return r
