"""The paper's design and stability numbers, computed and set beside the printed ones.

Each function returns a plain dict (JSON-ready); ``./ipfric design`` and
``./ipfric stability`` print them.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from . import paper
from .critical_delay import gain_critical_delay
from .estimation import coulomb_viscous, load_table5, load_table6, static_coefficient
from .linearize import jacobian
from .lqr import controllability_matrix, design
from .paperconfig import PaperConfig
from .stability import delta_thresholds


def _cmp(ours, printed) -> dict:
    ours = np.asarray(ours, float)
    printed = np.asarray(printed, float)
    with np.errstate(divide='ignore', invalid='ignore'):
        rel = np.where(printed != 0, np.abs(ours - printed) / np.abs(printed), np.abs(ours - printed))
    return {'ipfric': ours.round(6).tolist(), 'paper': printed.tolist(),
            'max_rel_diff': float(rel.max())}


def _eig_list(eigs) -> list:
    eigs = sorted(np.asarray(eigs, complex), key=lambda e: (-e.real, e.imag))
    return [[round(e.real, 6), round(e.imag, 6)] for e in eigs]


def design_report(cfg: PaperConfig, data_dir: str | Path | None = None) -> dict:
    """Gains (15), (23), (25), eigenvalues of section 4.2 and the appendix estimates."""
    out: dict = {'gains': {}, 'eigenvalues': {}, 'controllability_rank': {}}
    printed = {'viscous': paper.GAIN_15_VISCOUS, 'exponential': paper.GAIN_23_EXPONENTIAL,
               'dynamic': paper.GAIN_25_DYNAMIC}
    designs = {}
    for name, gain in printed.items():
        d = design(cfg.plant, cfg.friction[name], cfg.Q, cfg.R)
        designs[name] = d
        entry = _cmp(d.gain, gain)
        entry['equation'] = {'viscous': '(15)', 'exponential': '(23)', 'dynamic': '(25)'}[name]
        if d.reduced_gain is not None:
            entry['full_gain_with_z'] = d.full_gain.round(6).tolist()
        out['gains'][name] = entry
        A, B = jacobian(cfg.plant, cfg.friction[name])
        out['controllability_rank'][name] = {
            'rank': int(np.linalg.matrix_rank(controllability_matrix(A, B), tol=1e-9 * np.abs(A).max())),
            'n_states': int(A.shape[0])}
    A, B = jacobian(cfg.plant, cfg.friction['dynamic'])
    for label, gain, ref in [('dynamic_gain_15', paper.GAIN_15_VISCOUS, paper.EIG_DYNAMIC_GAIN_15),
                             ('dynamic_gain_25', paper.GAIN_25_DYNAMIC, paper.EIG_DYNAMIC_GAIN_25)]:
        K = np.zeros(5)
        K[:4] = gain[:4]
        eig = np.linalg.eigvals(A + B @ K[None, :])
        out['eigenvalues'][label] = {'ipfric': _eig_list(eig), 'paper': _eig_list(ref)}
    if data_dir is not None:
        out['friction_estimates'] = friction_estimates(cfg, data_dir)
    return out


def friction_estimates(cfg: PaperConfig, data_dir: str | Path) -> dict:
    """mu_c, eps (Table 5) and mu_s (Table 6) of the cart alone, F_N = M g."""
    data_dir = Path(data_dir)
    V, v, Va, va, suspect = load_table5(data_dir / 'table5_constant_voltage.csv')
    on_avg = coulomb_viscous(cfg.plant, Va, va)
    on_runs = coulomb_viscous(cfg.plant, V, v)
    s = static_coefficient(cfg.plant, load_table6(data_dir / 'table6_breakaway_voltage.csv'))
    return {
        'mu_s': {'ipfric': round(s['mu_s'], 6), 'std': round(s['mu_s_std'], 6), 'paper': paper.MU_S,
                 'mean_breakaway_V': round(s['mean_voltage'], 6), 'paper_mean_V': paper.BREAKAWAY_MEAN_V},
        'table5_row_averages': on_avg,
        'table5_individual_runs': on_runs,
        'table5_runs_set_aside': [{'voltage_V': a, 'value_mps': b, 'row_average_mps': c}
                                  for a, b, c in suspect],
        'paper': {'mu_c': paper.MU_C, 'eps': paper.EPS},
    }


def stability_report(cfg: PaperConfig) -> dict:
    """Routh-Hurwitz thresholds in delta (section 3.1) and the critical delays (section 5)."""
    expo = cfg.friction['exponential']
    th = delta_thresholds(cfg.plant, expo, paper.GAIN_15_VISCOUS)
    out = {'routh_hurwitz_gain_15_exponential': {
        'unstable_above_delta': {'ipfric': round(th['unstable_above'], 4), 'paper': paper.DELTA_UNSTABLE_ABOVE},
        'complex_pair_until_delta': {'ipfric': round(th['complex_until'], 4), 'paper': paper.DELTA_COMPLEX_UNTIL},
        'rhp_roots_beyond': th['rhp_roots']}}
    tau = {}
    for name, gain, ref in [('exponential', paper.GAIN_23_EXPONENTIAL, paper.TAU_C_EXPONENTIAL),
                            ('dynamic', paper.GAIN_25_DYNAMIC, paper.TAU_C_DYNAMIC)]:
        A, B = jacobian(cfg.plant, cfg.friction[name])
        r = gain_critical_delay(A, B, gain)
        tau[name] = {'ipfric': round(r['tau_c'], 6), 'paper': ref,
                     'crossing_frequency_hz': round(r['frequency_hz'], 4)}
        if name == 'dynamic':
            full = design(cfg.plant, cfg.friction[name], cfg.Q, cfg.R).full_gain
            r2 = gain_critical_delay(A, B, full)
            tau[name]['with_full_gain_incl_z'] = round(r2['tau_c'], 6)
    tau['exponential']['delta'] = expo.delta
    out['critical_delay_s'] = tau
    return out


def _num(value, unit: str, factor: float, digits: int = 3) -> str:
    return '-' if value is None else f'{factor * value:.{digits}g} {unit}'


def _hunting_row(label: str, h: dict) -> str:
    if h['source'] in ('rests', 'fallen', 'track_limit'):
        return f'| {label} | {h["source"].replace("_", " ")} | | | | | |'
    o, r = h['orbit'], h['run']
    if o:
        how = (f'periodic orbit, {"stable" if o["stable"] else "unstable"} (largest multiplier '
               f'{o["max_multiplier_modulus"]:.2g}), {o["sticks_per_period"]} sticking phases')
    else:
        how = f'{h["no_orbit"]}; the numbers are the run\'s, over its last {r["cycles"]} cycles'
    return (f'| {label} | {_num(h["x_p2p_m"], "cm", 100.0, 4)} | {_num(h["theta_p2p_rad"], "deg", 180 / np.pi)} | '
            f'{_num(h["period_s"], "s", 1.0, 4)} | {_num(h["stuck_fraction"], "%", 100.0, 2)} | '
            f'{_num(r.get("x_p2p_m"), "cm", 100.0, 4)} | {how} |')


def _edge_text(e: dict) -> str:
    if e['holds_to_s'] is None:
        return f'lost at the scenario\'s delay ({e["lost_from_s"] * 1e3:.1f} ms)'
    if e['lost_from_s'] is None:
        return f'holds over the whole scan (0-{e["max_delay_s"] * 1e3:.0f} ms)'
    text = f'{e["holds_to_s"] * 1e3:.1f} ms (lost from {e["lost_from_s"] * 1e3:.1f} ms)'
    if e['holds_again_s'] is not None:
        text += f'; holds again at {e["holds_again_s"] * 1e3:.0f} ms'
    return text


def check_page(result: dict, figure: str) -> str:
    """The Markdown page of a design check (``design.check.design_check``, with the command's
    ``scenario``, ``config``, ``axis``, ``encoders`` [m, rad]); ``figure``: the PNG's file name."""
    cases, i = result['cases'], result['nominal']
    c = cases[i]
    f = c['friction']
    enc = result['encoders']
    d = result['definitions']
    lines = [f'# Design check: {result["scenario"]}', '',
             f'`{result["config"]}`: gain K = [{", ".join(f"{k:.4g}" for k in result["gain"])}] '
             '(V/m, V/rad, V s/m, V s/rad), feedback delay '
             f'{result["delay_s"] * 1e3:g} ms, velocity filter {result["cutoff_hz"]:g} Hz, sample period '
             f'{result["sample_period_s"] * 1e3:g} ms; friction ' + ', '.join(f'{k} {v}' for k, v in f.items()) + '; '
             f'encoders {enc["cart_m"] * 1e3:.4g} mm and {np.degrees(enc["angle_rad"]):.4g} deg per count.', '',
             f'**Verdict**: {result["verdict"]}.', '', f'![design check]({figure})', '',
             f'## Hunting ({c["label"]})', '',
             '| sensors | cart p2p | angle p2p | period | stuck | run: cart p2p | how |',
             '| --- | --- | --- | --- | --- | --- | --- |',
             _hunting_row('exact', c['hunting']['exact']), _hunting_row('encoders', c['hunting']['encoders'])]
    df = c['describing_function']
    if df.get('intersection'):
        lines.append(f'| describing function (exact, sliding through v = 0) | {df["x_p2p_m"] * 100:.4g} cm | '
                     f'{np.degrees(df["theta_p2p_rad"]):.3g} deg | {df["period_s"]:.4g} s | - | | harmonic balance '
                     'of the friction law with the linear delayed loop |')
    else:
        lines.append(f'| describing function | - | | | | | {df.get("reason", "no intersection")} |')
    tau = c['linear_critical_delay']
    e = c['effective_delay']
    lines += ['', '## Delay', '', '| what | delay |', '| --- | --- |']
    for key, what in (('sliding', 'linear tau_c, eq. (27), sliding cart (c = beta + eps)'),
                      ('tanh', f'linear tau_c, eq. (27), sgn(v) -> tanh({tau["delta"]:g} v)')):
        t = tau[key]
        text = ('none below 200 rad/s' if t['tau_c'] is None else
                '0: the upright is unstable without delay' if t['tau_c'] == 0 else
                f'{t["tau_c"] * 1e3:.1f} ms (crossing at {t["frequency_hz"]:.2f} Hz)')
        lines.append(f'| {what} | {text} |')
    for kind in ('exact', 'encoders'):
        sensors = 'exact sensors' if kind == 'exact' else 'encoders'
        lines.append(f'| effective: holds the pendulum up to, {sensors} | {_edge_text(e[kind])} |')
        g = e[kind]
        if g['small_to_s'] is not None and g['grows_from_s'] is not None:
            within, verb = ((f'rests up to, {sensors}', 'hunts') if not g['reference_x_p2p_m'] else
                            (f'hunting within {d["growth"]:g}x of {g["reference_x_p2p_m"] * 100:.3g} cm up to, '
                             f'{sensors}', 'grows'))
            lines.append(f'| {within} | {g["small_to_s"] * 1e3:.1f} ms ({verb} from {g["grows_from_s"] * 1e3:.1f} '
                         'ms) |')
    fl = c['encoder_floor']
    hunt = c['numbers']['x_p2p_exact_m']
    lines += ['', 'The effective critical delay is measured, not linearized: runs of '
              f'{e["exact"]["run_s"]:g} s from the scenario\'s start at delays 0, {e["exact"]["step_s"] * 1e3:g} ms, '
              f'... {e["exact"]["max_delay_s"] * 1e3:g} ms, then bisected to {e["exact"]["tolerance_s"] * 1e3:g} ms '
              'above the scenario\'s delay (delays between samples delay the switch of the held voltage). '
              'A run holds the pendulum when it neither falls nor reaches the track limit.', '',
              '## Encoder floor', '',
              'The scenario\'s encoders on the same loop with the friction law made viscous only (static and '
              'Coulomb levels removed, eps kept): what quantization alone leaves, over the last '
              f'{d["cycles"]} cycles after {d["hold_seconds"]:g} s. Defined when that loop rests with exact '
              'sensors.', '']
    free = fl['exact_sensors']
    if not fl['defined']:
        lines.append(f'- not defined: with the friction law made viscous only the loop does not rest even with exact '
                     f'sensors (it {free["behaviour"].replace("_", " ")}' +
                     (f', cart p2p {free["x_p2p_m"] * 100:.3g} cm' if free.get('x_p2p_m') else '') +
                     '): the delay or the gain, not quantization, keep it moving')
    elif fl['behaviour'] == 'hunts':
        lines.append(f'- cart p2p {fl["x_p2p_m"] * 1e3:.3g} mm, angle p2p {np.degrees(fl["theta_p2p_rad"]):.3g} deg '
                     f'({fl["theta_p2p_rad"] / enc["angle_rad"]:.2g} angle counts), period {fl["period_s"]:.3g} s '
                     f'(spread {100 * fl["period_spread"]:.0f} %)' +
                     (f'; the friction hunting is {hunt / fl["x_p2p_m"]:.2g} times larger' if hunt else ''))
    else:
        lines.append(f'- {fl["behaviour"].replace("_", " ")}')
    heads = [k['label'] for k in cases]
    lines += ['', f'## Sensitivity: {result["axis"]}', '',
              '| quantity | ' + ' | '.join(heads) + ' | ' +
              ' | '.join(f'change, {k["label"]}' for j, k in enumerate(cases) if j != i) + ' |',
              '| --- |' + ' --- |' * (2 * len(cases) - 1)]
    for row in result['sensitivity']:
        vals = [_num(v, row['unit'], row['factor'], 4) for v in row['values']]
        ch = ['-' if x is None else f'{100 * x:+.0f} %' for j, x in enumerate(row['change']) if j != i]
        lines.append(f'| {row["what"]} | ' + ' | '.join(vals) + ' | ' + ' | '.join(ch) + ' |')
    lines += ['', '## How the numbers are made', '',
              '- Orbit: Newton on the return map of the sampled loop (design/orbit.py), from the cycle a run from '
              'the scenario\'s start settles into, when that run\'s cycles repeat. Where they do not (the encoders '
              f'make the cycle irregular), the run\'s last {d["cycles"]} cycles after {d["hold_seconds"]:g} s: '
              'peak-to-peak of the true states, mean time between rises of the angle through the middle of its '
              'swing.',
              '- Describing function (design/describing.py): the friction law broken out of the linear delayed '
              'loop, exact sensors, no sticking (the cart slides through v = 0).',
              '- Linear tau_c (design/critical_delay.py): the smallest delay at which a root of eq. (27) reaches '
              'the imaginary axis; the velocity filter is not in it.',
              f'- Hunting within {d["growth"]:g}x: the delay from which the cart p2p of a run exceeds '
              f'{d["growth"]:g} times its value at the scenario\'s delay.', '']
    return '\n'.join(lines)
