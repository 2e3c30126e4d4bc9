"""The design check's page and figure (``./ipfric design --check``): ``check.md``, ``check.png`` and
``check.json`` of a :func:`ipfric_core.study.check.design_check` result."""
from __future__ import annotations

import json
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from ..analysis.plots import save_figure

__all__ = ['check_page', 'check_figure', 'write_check']

#: the files of a check in its directory
FILES = {'page': 'check.md', 'figure': 'check.png', 'json': 'check.json'}


def write_check(result: dict, out: str | Path) -> dict:
    """Write the page, the figure and the numbers of ``result`` into ``out`` (created); their paths are
    set as ``result['files']`` and returned."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    result['files'] = {k: str(out / name) for k, name in FILES.items()}
    check_figure(result, out / FILES['figure'])
    (out / FILES['page']).write_text(check_page(result, FILES['figure']))
    (out / FILES['json']).write_text(json.dumps(result, indent=2, default=float))
    return result['files']


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
    """The Markdown page of a design check (:func:`ipfric_core.study.check.design_check`, with the command's
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
              '- Orbit: Newton on the return map of the sampled loop (study/orbit.py), from the cycle a run from '
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


def check_figure(result: dict, path: str | Path) -> Path:
    """The design check's figure (:func:`ipfric_core.study.check.design_check`): cart peak-to-peak and period of
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
    return save_figure(fig, path)
