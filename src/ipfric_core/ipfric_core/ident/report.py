"""Report of an identification: result.json, report.md and PNG figures in one directory."""
from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..physics.plant import cogging_amplitude_phase  # noqa: E402
from . import effects as fx  # noqa: E402
from . import shooting  # noqa: E402
from .equation_error import analyse, balance, errors, model_vectors, param_specs  # noqa: E402
from .residual import SIGNATURES, time_since_reversal  # noqa: E402

__all__ = ['save_figure', 'write_report']


def friction_summary(params: dict, active, normal_force: float) -> dict:
    """The friction as the paper's coefficients: mu_c, mu_s (F_N = ``normal_force``), eps, ..."""
    out = {'eps': params['eps'], 'normal_force_N': normal_force}
    if 'coulomb' in active:
        out['mu_c'] = params['Fc'] / normal_force
        out['mu_s'] = (params['Fc'] + params.get('Fs_excess', 0.0)) / normal_force
    for k in ('v_s', 'sigma0', 'sigma1'):
        if k in params:
            out[k] = params[k]
    if 'cogging' in active:
        out['cogging_amplitude_N'], out['cogging_phase_rad'] = cogging_amplitude_phase(params['cogging_sin_N'],
                                                                                       params['cogging_cos_N'])
    return out


def result_dict(res: dict) -> dict:
    """The JSON-ready result (keys listed in docs/identification.md)."""
    pe, pv = res['prepared']
    base, fit = res['base_fit'], res['fit']
    units = {s.name: s.unit for s in param_specs(fit.active)}
    a0, a1 = analyse(pe, base), analyse(pe, fit)
    win = shooting.cart_windows(pv.rec)
    return {
        'data': {'estimation': pe.rec.name, 'validation': pv.rec.name, 'samples_used': [pe.n_used, pv.n_used],
                 'cutoff_hz': pe.rec.cutoff_hz, 'decimation': pe.q, 'stick_velocity_mps': pe.rec.stick_velocity},
        'base_model': res['base_model'],
        'effects_added': [e for e in fit.active if e not in base.active],
        'params': {k: {'value': v, 'std': fit.std[k], 'unit': units[k]} for k, v in fit.params.items()},
        'friction': friction_summary(fit.params, fit.active, pe.rec.normal_force),
        'error_before': {'estimation': errors(pe, base.params, base.active),
                         'validation': errors(pv, base.params, base.active)},
        'error_after': {'estimation': errors(pe, fit.params, fit.active),
                        'validation': errors(pv, fit.params, fit.active)},
        'simulation_error': shooting.summary(
            shooting.predict(model_vectors(pv.rec, fit.params, fit.active), pv.rec, win), pv.rec, win, 'x'),
        'residual_white_before': a0['whiteness']['white'],
        'residual_white_after': a1['whiteness']['white'],
        'effects_tried': res['tried'],
        'signatures_before': a0['signatures'], 'signatures_after': a1['signatures'],
        'whiteness_before': {k: v for k, v in a0['whiteness'].items() if k not in ('acf', 'ccf')},
        'whiteness_after': {k: v for k, v in a1['whiteness'].items() if k not in ('acf', 'ccf')},
    }


def _signature_axis(name: str, b, pr):
    u = b.used
    sig = fx.EFFECTS[name].signature
    if sig in ('velocity_sign', 'speed', 'direction'):
        return b.v[u], 'velocity (m/s)'
    if sig == 'reversal':
        return np.minimum(time_since_reversal(pr.t[u], b.v[u]), 0.5), 'time since reversal (s)'
    if sig == 'position':
        return b.x[u], 'position (m)'
    if sig == 'voltage':
        return pr.u_raw[u], 'input u'
    if sig == 'lag':
        return np.gradient(pr.uf)[u] / pr.dt, 'input rate (unit/s)'
    return pr.t[u], 'time (s)'


def figures(res: dict, out: Path) -> list[str]:
    """fit.png, residual.png, autocorrelation.png and one signature_<effect>.png per effect."""
    pe, _ = res['prepared']
    base, fit = res['base_fit'], res['fit']
    b0, b1 = balance(pe, base.params, base.active), balance(pe, fit.params, fit.active)
    files = []
    fig, ax = plt.subplots(figsize=(10, 4))
    ax.plot(pe.t, b1.y, lw=0.7, label='input force (measured)')
    ax.plot(pe.t, b1.model, lw=0.7, label='model: ' + '+'.join(('base',) + fit.active))
    ax.set(xlabel='time (s)', ylabel='force (N)', title='force balance on the estimation data')
    ax.legend()
    files.append(save_figure(fig, out / 'fit.png'))
    fig, ax = plt.subplots(figsize=(10, 4))
    ax.plot(pe.t[b0.used], b0.r[b0.used], '.', ms=2, label=f'before ({res["base_model"]})')
    ax.plot(pe.t[b1.used], b1.r[b1.used], '.', ms=2, label='after')
    ax.set(xlabel='time (s)', ylabel='residual (N)', title='residual before and after the search')
    ax.legend()
    files.append(save_figure(fig, out / 'residual.png'))
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for a, key, lab in ((ax[0], 'acf', 'autocorrelation'), (ax[1], 'ccf', 'cross-correlation with u')):
        for tag, fb in (('before', base), ('after', fit)):
            w = analyse(pe, fb)['whiteness']
            y = np.array(w[key])
            lags = np.arange(len(y)) if key == 'acf' else np.arange(len(y)) - w['max_lag']
            a.plot(lags * pe.dt, y, 'o-', ms=3, label=tag)
        a.axhspan(-w['band'], w['band'], color='0.85', label='95 % band')
        a.set(xlabel='lag (s)', title=lab)
        a.legend()
    files.append(save_figure(fig, out / 'autocorrelation.png'))
    for prev, name in zip(res['steps'], [e for e in fit.active if e not in base.active]):
        bp = balance(pe, prev.params, prev.active)  # the residual before the effect was added
        var, label = _signature_axis(name, bp, pe)
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(var, bp.r[bp.used], '.', ms=2)
        ax.set(xlabel=label, ylabel='residual (N)',
               title=f'{name}: residual against {SIGNATURES[fx.EFFECTS[name].signature]}')
        files.append(save_figure(fig, out / f'signature_{name}.png'))
    return files


def save_figure(fig, path: Path) -> str:
    """Write ``fig`` as a PNG and close it; returns the path."""
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return str(path)


def markdown(r: dict) -> str:
    """report.md: errors, effects tried, parameters with standard errors, friction."""
    lines = [f'# Identification: {r["data"]["estimation"]}', '',
             f'Base model `{r["base_model"]}`; effects added: '
             + (', '.join(f'`{e}`' for e in r['effects_added']) or 'none') + '.', '',
             '| error | estimation RMS (N) | estimation % | validation RMS (N) | validation % |',
             '| --- | --- | --- | --- | --- |']
    for tag in ('error_before', 'error_after'):
        e = r[tag]
        lines.append(f'| {tag.split("_")[1]} | {e["estimation"]["rms"]:.4g} '
                     f'| {e["estimation"]["relative_percent"]:.3f} '
                     f'| {e["validation"]["rms"]:.4g} | {e["validation"]["relative_percent"]:.3f} |')
    s = r['simulation_error']
    lines += ['', f'Simulation error on the validation data (multiple shooting, {s["x_windows"]} windows): '
              f'{s["x_rms_counts"]:.3g} encoder counts RMS, {s["x_percent"]:.3g} % of the motion within the windows.']
    lines += ['', f'Residual white before: {r["residual_white_before"]}, after: {r["residual_white_after"]} '
              f'(autocorrelation lags outside the 95 % band: {r["whiteness_before"]["acf_outside"]} -> '
              f'{r["whiteness_after"]["acf_outside"]} of {r["whiteness_after"]["max_lag"]}).', '',
              '## Effects tried', '', '| effect | estimation gain % | validation gain % | p | kept |',
              '| --- | --- | --- | --- | --- |']
    for t in r['effects_tried']:
        lines.append(f'| {t["name"]} | {t["estimation_gain_percent"]:.2f} | {t["validation_gain_percent"]:.2f} '
                     f'| {t["validation_p"]:.2g} | {t["kept"]} |')
    lines += ['', '## Parameters', '', '| name | value | std | unit |', '| --- | --- | --- | --- |']
    for k, p in r['params'].items():
        lines.append(f'| {k} | {p["value"]:.6g} | {p["std"]:.3g} | {p["unit"]} |')
    lines += ['', '## Friction as coefficients', '']
    lines += [f'- {k}: {v:.6g}' for k, v in r['friction'].items()]
    lines += ['', '## Signature scores of the final residual (share of its variance, 0..1)', '']
    lines += [f'- {SIGNATURES[k]}: {v:.3f}' for k, v in r['signatures_after']['scores'].items()]
    lines += ['', 'Figures: fit.png, residual.png, autocorrelation.png, signature_<effect>.png.', '']
    return '\n'.join(lines)


def write_report(res: dict, out: str | Path, plots: bool = True, result=None, figs=None, text=None) -> dict:
    """Write result.json, report.md and the figures into ``out``; return the result dict.

    ``result``, ``figs``, ``text``: the functions that make the result dict, the figures and the
    Markdown (default: this module's, an equation-error search; a ladder passes its own)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    r = (result or result_dict)(res)
    r['figures'] = (figs or figures)(res, out) if plots else []
    r['files'] = {'report': str(out / 'report.md'), 'result': str(out / 'result.json')}
    (out / 'result.json').write_text(json.dumps(r, indent=2, default=float))
    (out / 'report.md').write_text((text or markdown)(r))
    return r
