"""Randomised identification campaign: cases drawn by ``tests/independent/campaign.py`` (code
that shares nothing with ipfric_core), each identified by ``ipfric identify`` and scored.

    python -m bench.ident_campaign --out runs/campaign --cases 40 --seed 1 [--threshold 2]
    python -m bench.ident_campaign --out runs/campaign --rescore      # score existing results again
    python -m bench.ident_campaign --out runs/campaign --cases 200 --seed 1 --resume   # go on after a stop
    python -m bench.ident_campaign --out runs/all --merge runs/part1 runs/part2/summary.json   # one summary
    python -m bench.ident_campaign --out runs/rest --cases 200 --seed 2027 --except bench/campaign/seed2027.json
                                                  # the cases a kept part does not hold (same code)
    python -m bench.ident_campaign --out runs/now --newest bench/campaign/seed2027-*.json
                                                  # each case's newest answer over parts of several codes

A case's expected answer: the library effect(s) whose own contribution (truth
``contribution_counts_rms``: multiple shooting on 1 s windows, cart encoder counts; angle counts
for ``sensor_bias``) reaches the threshold, and a wrong declared constant the ladder corrects (M,
alpha, beta: ``<name> corrected``); ``not_explained`` when only an effect from outside the library
(spring, friction patch) or a wrong pendulum constant (m, l) reaches it; ``none`` otherwise.
Below the threshold any answer but a wrong library name is acceptable (recorded as such).
The answer given: ``result['effects_added']`` (the friction law's parts ``coulomb``, ``stribeck``,
``presliding`` are not effects) and ``result['constants_corrected']``; without either,
``not_explained`` when its verdict says so, else ``none``.

On the clean cases the summary also checks the final friction levels' reported standard errors against
the truth (``coverage``: the median |fit - truth| / std and the share within two of them, per experiment).

Writes out_dir/summary.json, summary.md and detection.png; out_dir/cases/<case>/ holds the data,
the truth and the identification's report (``ident/result.json``, ``ident/stderr.txt``).
"""
from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import platform
import subprocess
import sys
import time
from collections import Counter, defaultdict
from pathlib import Path

import numpy as np

from bench.independent_code import campaign

ROOT = Path(__file__).resolve().parents[1]

FRICTION_PARTS = {'coulomb', 'stribeck', 'presliding'}
OUTSIDE = set(campaign.OUTSIDE) | {'plant_error'}
#: declared constants the ladder tries to correct (ipfric_core.ident.hypotheses.PLANT_CORRECTIONS), and their answers
CORRECTED = ('M', 'alpha')
CORRECTIONS = tuple(f'{n} corrected' for n in CORRECTED)
#: a wrong declared constant that a fitted friction parameter takes over exactly: the back-EMF beta and
#: the viscous slope eps act as one (F = alpha V - (beta + eps) x'), so the refit explains it (eps, or beta
#: itself where the data want less than the declared beta: ipfric_core.ident.hypotheses.beta_for_eps) and
#: no answer about it is wrong, nor is its correction an answer
EQUIVALENT = ('beta',)
#: a wrong declared constant that two corrections take over exactly: the pendulum's mass m enters the cart's
#: equation only (the pendulum's own, divided by m l, is free of it), so m declared k times its true value is
#: the cart's equation times k: M and alpha corrected by k (the friction and beta + eps with them)
SCALED = {'m': ('M corrected', 'alpha corrected')}
#: an effect's part that a nearer model without it leaves (truth key, that model): it counts by the smaller
#: of its whole contribution and that part (:func:`components`)
OWN_PART = {'drive_backlash': ('play_contribution_counts_rms', 'a cart heavier by its motor side'),
            'deadzone': ('beyond_friction_counts_rms', 'a Coulomb level higher by alpha dz')}
THRESHOLD = 2.0          # counts RMS: an effect's contribution from which it must be named
#: the smallest play [encoder counts] an encoder shows as a play (ipfric_core.ident.refutations refutes a
#: drive play under two counts): a smaller one, whatever its contact's ringing does, is scored as the cart
#: heavier by the motor side
MIN_PLAY_COUNTS = 2.0
#: the answer of a drive whose play the final model holds closed (a compliant contact without play): the two-mass
#: drive of a play the encoder shows no play of or that does less than the threshold beyond the contact, named
#: with its ringing; a drive whose play does more, missed
CLOSED_DRIVE = 'drive_backlash (play closed)'
#: a spring's mean pull over the record (truth ``mean_pull_N``, F_pre - k mean(x), where its part
#: ``mean_pull_contribution_counts_rms`` reaches the threshold) is a constant force: an offset fitted within this
#: factor of it, of its sign, names that part of the spring where no offset (nor what acts alike) is expected of
#: the library (seed 2027's case 38: 0.00338 N against a mean pull of 0.0034 N); not naming it is no miss (the
#: spring's pull along the track, which no library model holds, hides it from a model without one: case 157's
#: offset gained nothing)
PULL_FACTOR = 2.0
BINS = (0.0, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 1000.0, math.inf)
TIMEOUT = 1800.0


def library_names() -> set[str]:
    """The identification's effect library (the friction law's parts left out)."""
    from ipfric_core.ident.effects import EFFECTS
    return set(EFFECTS) - FRICTION_PARTS


# ------------------------------------------------------------------------------------ answers
def components(truth: dict, threshold: float = THRESHOLD) -> list[dict]:
    """Every undeclared discrepancy of a case: effects and a wrong declared constant. A two-mass drive
    whose play alone (truth ``play_contribution_counts_rms``: the drive against its motor side fixed to
    the cart) stays below ``threshold``, or whose play is under MIN_PLAY_COUNTS encoder counts, is a cart
    heavier by the motor side's mass: ``M corrected`` (or, under MIN_PLAY_COUNTS, the drive with its play
    closed, :data:`CLOSED_DRIVE`, alike); one whose play does less than ``threshold`` beyond the same drive
    with its play closed (truth ``closed_contribution_counts_rms``) is a compliant contact without play:
    :data:`CLOSED_DRIVE` (the drive with its play named, alike); else it
    counts by its play alone (the heavier cart takes the rest over). A deadzone counts by what neither
    model without it takes over: the smaller of its whole contribution and what it does beyond a Coulomb
    level higher by alpha dz (truth ``beyond_friction_counts_rms``: the friction every identification
    refits takes that part over; in a closed loop the shifted level can move the motion more than the
    deadzone itself, and the model without it is then the nearer one)."""
    out = []
    for k, v in truth['effects'].items():
        comp = dict(name=k, library=bool(v['library']), counts=float(v['contribution_counts_rms']))
        key, nearer = OWN_PART.get(k, ('', ''))
        part = v.get(key)
        play = v['gap_m'] / truth['encoder']['x_count_m'] if k == 'drive_backlash' and 'gap_m' in v else math.inf
        if k == 'drive_backlash' and threshold <= comp['counts'] and (part is not None and part < threshold
                                                                      or play < MIN_PLAY_COUNTS):
            why = (f'a play of {play:.2g} encoder counts (the encoder shows no play under {MIN_PLAY_COUNTS:g})'
                   if play < MIN_PLAY_COUNTS else f'a drive play of {part:.2g} counts')
            comp.update(name='M corrected', detail=f'{why}: the motor side ({v["motor_mass_kg"]:.3g} kg) moves '
                        'with the cart', alike=[CLOSED_DRIVE] if play < MIN_PLAY_COUNTS else [])
        elif k == 'drive_backlash' and threshold <= comp['counts'] and part is not None and \
                v.get('closed_contribution_counts_rms', math.inf) < threshold:
            comp.update(name=CLOSED_DRIVE, counts=min(comp['counts'], float(part)), alike=['drive_backlash'],
                        detail=f'a drive play of {part:.2g} counts beyond a heavier cart, '
                               f'{v["closed_contribution_counts_rms"]:.2g} beyond its contact with the play closed')
        elif part is not None:
            comp.update(counts=min(comp['counts'], float(part)),
                        detail=f'{comp["counts"]:.3g} counts, {part:.3g} of them beyond {nearer}')
        if k == 'spring' and v.get('mean_pull_contribution_counts_rms', 0.0) >= threshold:
            comp.update(pull_N=float(v['mean_pull_N']),
                        detail=f'a mean pull of {v["mean_pull_N"]:.3g} N (a constant force: an offset), '
                               f'{v["mean_pull_contribution_counts_rms"]:.3g} counts of it')
        out.append(comp)
    pe = truth.get('plant_error')
    if pe:
        known = pe['name'] in CORRECTED or pe['name'] in EQUIVALENT
        out.append(dict(name=f'{pe["name"]} corrected' if known else 'plant_error', library=known,
                        counts=float(pe['contribution_counts_rms']), equivalent=pe['name'] in EQUIVALENT,
                        same_as=sorted(SCALED.get(pe['name'], ())),
                        detail=f'{pe["name"]} declared x{pe["factor"]:.2f}'))
    return out


def expected_answer(truth: dict, threshold: float = THRESHOLD) -> dict:
    comps = components(truth, threshold)
    seen = [c for c in comps if not c.get('equivalent')]
    above = sorted(c['name'] for c in seen if c['library'] and c['counts'] >= threshold)
    outside = sorted(c['name'] for c in seen if not c['library'] and c['counts'] >= threshold)
    below = sorted(c['name'] for c in comps if c['counts'] < threshold or c.get('equivalent'))
    label = '+'.join(above) if above else ('not_explained' if outside else 'none')
    # the corrections that are the same model as the only discrepancy, a wrong constant (:data:`SCALED`)
    same = [c.get('same_as', []) for c in seen if not c['library'] and c['counts'] >= threshold]
    # the other names of a library answer (a drive below the encoder's play: its play closed)
    alike = {n: c['name'] for c in seen if c['library'] and c['counts'] >= threshold for n in c.get('alike', ())}
    pull = [c['pull_N'] for c in comps if 'pull_N' in c]
    # one correction that replays every discrepancy from outside the library within the threshold (a wrong
    # pendulum mass with what else is outside: truth ``one_correction_counts_rms``) is another name of them, and
    # so is the pair of corrections (it holds every model of either)
    nearest = (truth.get('plant_error') or {}).get('one_correction_counts_rms') or {}
    single = sorted(n for n, c in nearest.items() if c < threshold)
    return dict(label=label, library=above, outside=outside, below=below, alike=alike,
                same_as=same[0] if not above and len(same) == 1 else [],
                clean=not comps, pendulum=truth.get('pendulum_attached', True),
                pull_N=pull[0] if pull else None, single=single)


def predicted_answer(result: dict | None) -> dict:
    if result is None:
        return dict(label='error', added=[], verdict=None, offset_N=None)
    from ipfric_core.ident.refutations import CLOSED_PLAY
    final = {p['name']: p for p in (result.get('ladder') or [{}])[-1].get('params', [])}
    play = final.get('drive_backlash_m')
    closed = play is not None and not play['fitted'] and play['value'] <= CLOSED_PLAY
    added = sorted([CLOSED_DRIVE if e == 'drive_backlash' and closed else e
                    for e in result.get('effects_added', []) if e not in FRICTION_PARTS]
                   + [f'{n} corrected' for n in result.get('constants_corrected', []) if n not in EQUIVALENT])
    verdict = result.get('verdict')
    offset = final.get('offset_N', {}).get('value') if 'offset' in added else None
    return dict(label=answer_label(added, verdict), added=added, verdict=verdict, offset_N=offset)


def answer_of(row: dict) -> dict:
    """The answer (:func:`predicted_answer`'s) a case's row holds."""
    return dict(label=row['predicted'], added=row['added'], verdict=row['verdict'], offset_N=row.get('offset_N'))


def not_explained(row: dict) -> bool:
    """Whether a case's row says "not explained" once an offset naming a spring's mean pull is set aside
    (:func:`pull_named`)."""
    return pull_named(row['expected_detail'], answer_of(row))['label'] == 'not_explained'


def answer_label(added: list, verdict) -> str:
    """The answer's name: the effects and corrections ``added``; without any, ``not_explained`` where the
    verdict says so, else ``none``."""
    if added:
        return '+'.join(added)
    return 'not_explained' if isinstance(verdict, dict) and verdict.get('explained') is False else 'none'


def pull_named(expected: dict, predicted: dict) -> dict:
    """``predicted`` without an offset that names a spring's mean pull (:data:`PULL_FACTOR`) where the library
    expects no offset (nor what acts alike): that part of the spring is named right, and the answer is scored
    on the rest."""
    pull, off = expected.get('pull_N'), predicted.get('offset_N')
    pendulum = expected.get('pendulum', True)
    if pull is None or off is None or off * pull <= 0 or not 1 / PULL_FACTOR <= off / pull <= PULL_FACTOR \
            or _kind('offset', pendulum) in {_kind(n, pendulum) for n in expected['library']}:
        return predicted
    added = [n for n in predicted['added'] if n != 'offset']
    return dict(predicted, added=added, label=answer_label(added, predicted['verdict']), offset_N=None)


#: effects that act alike and are told apart only by a small part: a friction level (1 + a) Fc forward and
#: (1 - a) Fc backward is Fc plus a constant force -a Fc while the cart slides; only a (Fs - Fc) (the
#: Stribeck part, the static levels) tells the direction dependence from an offset. A transport delay d
#: and a first-order lag of the command (ipfric's ``lag``, which the generator never draws) with the same
#: d: exp(-s d) and 1 / (1 + s d) part at the order (s d)^2 / 2, below 1e-3 for a delay of a sample or two
#: at the cart's bandwidth
ALIKE = ({'asymmetry', 'offset'}, {'delay', 'lag'})
#: on the cart alone the data fix M / alpha only ((M / alpha) x'' = V - ((beta + eps) / alpha) x' - F / alpha):
#: a wrong alpha answered with M corrected (the friction scaled with it) is the same model, and the reverse
CART_ALIKE = ({'M corrected', 'alpha corrected'},)


#: the outcomes counted right
RIGHT = ('correct', 'alike', 'acceptable')


def _kind(name: str, pendulum: bool = True) -> str:
    """The name of the group of answers that act alike (:data:`ALIKE`, :data:`CART_ALIKE` without a
    pendulum) that ``name`` belongs to, else ``name``."""
    groups = ALIKE if pendulum else ALIKE + CART_ALIKE
    return next(('/'.join(sorted(g)) for g in groups if name in g), name)


def named_kinds(expected: dict, added: list) -> list[str]:
    """The groups (:func:`_kind`) of the answers ``added``, each read as the effect of ``expected`` it is
    another name of (``expected['alike']``: a drive's play closed for a heavier cart, and the reverse)."""
    alike = expected.get('alike', {})
    return [_kind(alike.get(n, n), expected.get('pendulum', True)) for n in added]


def outcome(expected: dict, predicted: dict) -> str:
    """correct | alike (an effect that acts alike named: :data:`ALIKE`; a drive below the encoder's play
    named with its play closed, :data:`CLOSED_DRIVE`; or, for a wrong constant, the
    corrections that are the same model: :data:`SCALED`, or the one correction that replays it and every
    other discrepancy from outside the library within the threshold) | acceptable (below threshold) | partial |
    false_positive | missed | wrong | error. An offset that names a spring's mean pull is set aside
    (:func:`pull_named`)."""
    predicted = pull_named(expected, predicted)
    e, p = expected['label'], predicted['label']
    if p == 'error':
        return 'error'
    if p == e:
        return 'correct'
    if expected['library'] and predicted['added'] and sorted(named_kinds(expected, predicted['added'])) == \
            sorted(_kind(n, expected['pendulum']) for n in expected['library']):
        return 'alike'
    if e == 'none':
        if expected['clean']:
            return 'false_positive'
        if p == 'not_explained' or set(predicted['added']) <= set(expected['below']):
            return 'acceptable'
        return 'wrong'
    if e == 'not_explained':
        if expected.get('same_as') and sorted(predicted['added']) == expected['same_as']:
            return 'alike'
        added = set(predicted['added'])
        if expected.get('single') and (added == set(CORRECTIONS) or len(added) == 1 and
                                       added <= set(expected['single'])):
            return 'alike'
        return 'missed' if p == 'none' else 'wrong'
    if p in ('none', 'not_explained'):
        return 'missed'
    if set(predicted['added']) & set(expected['library']):
        return 'partial'
    return 'wrong'


# ------------------------------------------------------------------------------ identification
def identify_command(case_dir: Path, truth: dict) -> list[str]:
    cmd = ['identify', str(case_dir / 'data.csv'), '--plant', str(case_dir / 'plant.yaml'),
           '--out', str(case_dir / 'ident'), '--no-plots', '--json']
    if not truth['pendulum_attached']:
        cmd.append('--cart-alone')
    return cmd


#: the paths whose code makes a case and its answer: the identification (with the physics it calls) and
#: the independent generator; a commit that touches only others (docs, the scorer, ROS) keeps the answers
ANSWER_PATHS = ('src/ipfric_core', 'tests/independent')


def code_commit() -> str:
    """The last commit that changed :data:`ANSWER_PATHS` (``+dirty`` when they have uncommitted changes;
    ``unknown`` outside git): a campaign continued with --resume must be one code's answers."""
    try:
        head = subprocess.run(['git', 'log', '-1', '--format=%h', '--', *ANSWER_PATHS], cwd=ROOT,
                              capture_output=True, text=True, check=True).stdout.strip()
        dirty = subprocess.run(['git', 'status', '--porcelain', '--untracked-files=no', '--', *ANSWER_PATHS],
                               cwd=ROOT, capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return 'unknown'
    return (head or 'unknown') + ('+dirty' if dirty else '')


def identify_case(case_dir: Path, truth: dict, timeout: float = TIMEOUT, threads: int | None = None) -> dict:
    """Run ``ipfric identify`` on a case in a subprocess (its simulations on ``threads`` threads: by default
    numba's own choice, every core); its result.json (or None), wall time, exit code and the last lines of
    its standard error."""
    cmd = identify_command(case_dir, truth)
    env = dict(os.environ, OPENBLAS_NUM_THREADS='1', MKL_NUM_THREADS='1')
    if threads is not None:
        env['NUMBA_NUM_THREADS'] = str(threads)
    (case_dir / 'ident').mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    rc: int | str
    try:
        proc = subprocess.run([sys.executable, '-m', 'ipfric_core.cli', *cmd], cwd=ROOT, env=env,
                              capture_output=True, text=True, timeout=timeout)
        rc, err = proc.returncode, proc.stderr
    except subprocess.TimeoutExpired as exc:
        rc, err = 'timeout', (exc.stderr or b'').decode() if isinstance(exc.stderr, bytes) else (exc.stderr or '')
    wall = time.perf_counter() - t0
    (case_dir / 'ident' / 'stderr.txt').write_text(err or '')
    path = case_dir / 'ident' / 'result.json'
    result = None
    if rc == 0 and path.exists():
        result = json.loads(path.read_text())
    tail = [ln for ln in (err or '').strip().splitlines() if ln.strip()][-3:]
    return dict(result=result, wall_s=round(wall, 2), rc=rc, stderr_tail=tail,
                command='./ipfric ' + ' '.join(cmd))


# ----------------------------------------------------------------------------------- the oracle
def oracle_model_values(truth: dict) -> tuple[dict, list[tuple[str, dict]]]:
    """The truth in the identification's own parameters: friction levels [N] and each library
    effect with its values (effects from outside the library have no such parameters)."""
    fr = truth['friction']
    values = {'Fc': fr['Fc'], 'Fs_excess': fr['Fs_excess'], 'eps': fr['eps'], 'v_s': fr['v_s']}
    effects = []
    for name, q in sorted(truth['effects'].items()):
        if name == 'deadzone':
            effects.append((name, {'deadzone_V': q['dz_V']}))
        elif name == 'saturation':
            effects.append((name, {'saturation_V': q['u_max_V']}))
        elif name == 'delay':
            effects.append((name, {'input_delay_s': q['delay_s']}))
        elif name == 'cogging':
            a = q['amplitude_N']
            effects.append((name, {'cogging_sin_N': a * math.cos(q['phase_rad']),
                                   'cogging_cos_N': a * math.sin(q['phase_rad']), 'cogging_period_m': q['period_m']}))
        elif name == 'asymmetry':
            effects.append((name, {'asymmetry': q['a'], 'asymmetry_viscous_Ns_per_m': 0.0}))
        elif name == 'offset':
            effects.append((name, {'offset_N': q['F0_N']}))
        elif name == 'sensor_bias':
            effects.append((name, {'bias_theta_rad': q['theta_bias_rad']}))
        elif name == 'drive_backlash':
            effects.append((name, drive_values(q)))
    return values, effects


def drive_values(q: dict) -> dict:
    """An independent generator's drive with play (play ``gap_m``, ``motor_mass_kg``, contact ``k_N_per_m`` and
    ``c_N_s_per_m``) in the identification's parameters."""
    return {'drive_backlash_m': q['gap_m'], 'drive_mass_kg': q['motor_mass_kg'],
            'drive_stiffness_N_per_m': q['k_N_per_m'], 'drive_damping_Ns_per_m': q['c_N_s_per_m']}


def oracle(case_dir: Path, truth: dict, split: float = 0.6) -> dict:
    """The identification's validation simulation error of the TRUE model (true constants, friction
    and library effects; an outside effect left out): what its ladder could reach at best on this
    file with its own loader and metric. Far above the encoders' rounding on a case whose effects
    are all in the library, it says the data hold something the identification's model does not
    represent (a hanging pendulum read as upright, a zeros angle column taken for a pendulum)."""
    try:
        from ipfric_core.analysis.records import load
        from ipfric_core.ident.model import load_declared
        from ipfric_core.ident.problem import Problem
        from ipfric_core.physics.params import PlantParams
        plant = PlantParams(**truth['constants'])
        rec = load(case_dir / 'data.csv', plant, None, not truth['pendulum_attached'])
        _, val = rec.split(split)
        values, effects = oracle_model_values(truth)
        model = load_declared(None, 'exponential', rec.theta is not None, plant).with_values(values)
        for name, q in effects:
            model = model.with_effect(name, q)
        out = Problem(val).summary(model)
        return {k: float(v) for k, v in out.items() if isinstance(v, (int, float))}
    except Exception as exc:      # noqa: BLE001  (a refused file: the identification's message)
        return {'error': f'{type(exc).__name__}: {exc}'}


# ------------------------------------------------------------------------------------- scoring
def score_case(truth: dict, ident: dict, threshold: float = THRESHOLD, generation_s: float | None = None,
               oracle_counts: dict | None = None, data_sha256: str | None = None) -> dict:
    """One case's row: its truth's components and expected answer, the identification's answer and outcome;
    ``data_sha256``: the digest of the data the identification read (:func:`data_digest`)."""
    exp = expected_answer(truth, threshold)
    pred = predicted_answer(ident.get('result'))
    res = ident.get('result') or {}
    ladder = [(s['step'], round(s['validation']['x_rms_counts'], 3)) for s in res.get('ladder', [])]
    return dict(
        case=truth['case'], index=truth['index'], experiment=truth['experiment'],
        theta_column=truth['theta_column'], sample_period_s=truth['sample_period_s'],
        duration_s=truth['duration_s'], timing=truth['timing']['kind'],
        components=components(truth, threshold), expected=exp['label'], expected_detail=exp,
        predicted=pred['label'], added=pred['added'], verdict=pred['verdict'], offset_N=pred['offset_N'],
        outcome=outcome(exp, pred), validation_counts=ladder, oracle_counts=oracle_counts,
        friction_z=friction_z(truth, ident.get('result')),
        wall_s=ident.get('wall_s'),
        generation_s=generation_s if generation_s is not None else truth.get('generation_s'),
        rc=ident.get('rc'), stderr_tail=ident.get('stderr_tail'),
        command=ident.get('command'), data_sha256=data_sha256)


def data_digest(case_dir: Path) -> str:
    """SHA-256 of a case's data.csv: which draw a row scored. The generator gives the same bytes for the same
    (seed, index) on one machine; a balancing loop's bytes differ between machines whose floating point
    differs (the loop amplifies the last bit: docs/identification.md), an open-loop case's do not."""
    return hashlib.sha256((case_dir / 'data.csv').read_bytes()).hexdigest()


def machine() -> dict:
    """The machine a part ran on (its processor and its vector extensions, named as numpy names them: AVX2,
    FMA3): what a balancing loop's draw depends on (:func:`data_digest`)."""
    info = Path('/proc/cpuinfo')
    lines = info.read_text().splitlines() if info.exists() else []

    def field(name: str) -> str:
        return next((ln.split(':', 1)[1].strip() for ln in lines if ln.split(':', 1)[0].strip() == name), '')
    simd = {'FMA3' if f == 'fma' else f.upper() for f in field('flags').split() if f.startswith(('avx', 'fma'))}
    return dict(cpu=field('model name') or platform.processor(), arch=platform.machine(), numpy=np.__version__,
                simd=sorted(simd))


#: the ladder's law that is the generator's (the exponential Stribeck curve, gamma 2): the friction levels of a
#: final model with another law mean other things and are not checked against the truth
LAW = 'exponential'
#: the share of the levels a standard error must cover within two of them (a normal error: 95 %)
COVERED = 2.0


def friction_z(truth: dict, result: dict | None) -> dict:
    """The final model's friction levels off the truth in their standard errors, (fit - truth) / std, where the
    final law is the generator's (the friction parameters of LAW, no other) and a level has a finite standard
    error; {} otherwise."""
    from ipfric_core.ident.model import FRICTION_FITTED, LAW_PARAMS
    if not result or not result.get('ladder'):
        return {}
    params = {p['name']: p for p in result['ladder'][-1]['params']}
    if set(params) & set(FRICTION_FITTED) != set(LAW_PARAMS[LAW]):
        return {}
    out = {}
    for n in LAW_PARAMS[LAW]:
        p = params[n]
        s = p.get('std')
        if p.get('fitted') and s is not None and math.isfinite(s) and s > 0:
            out[n] = (p['value'] - truth['friction'][n]) / s
    return out


def coverage(cases: list[dict]) -> dict:
    """How well the reported standard errors of the friction levels cover the truth on the clean cases (where
    the levels are the whole truth): per experiment and over all, the levels checked, the median |z| (0.67 for
    honest normal errors) and the share within COVERED standard errors (0.95)."""
    groups: defaultdict[str, list] = defaultdict(list)
    for c in cases:
        if c['components'] or not c.get('friction_z'):
            continue
        z = [abs(v) for v in c['friction_z'].values()]
        groups[c['experiment']] += z
        groups['all'] += z
    return {k: dict(n=len(z), median_abs_z=float(np.median(z)), within=float(np.mean(np.array(z) <= COVERED)))
            for k, z in sorted(groups.items())}


def detection_limit(points: list[tuple[float, bool]], share: float = 0.95, least: int = 3):
    """Smallest contribution c such that of the cases at or above c at least ``share`` are named
    right (and at least ``least`` such cases); None when no such c."""
    pts = sorted(points)
    for i, (c, _) in enumerate(pts):
        tail = [ok for _, ok in pts[i:]]
        if len(tail) >= least and sum(tail) / len(tail) >= share:
            return c
    return None


def summarize(cases: list[dict], threshold: float, meta: dict) -> dict:
    confusion: defaultdict[str, Counter] = defaultdict(Counter)
    for c in cases:
        confusion[c['expected']][c['predicted']] += 1
    per_effect = defaultdict(list)        # name -> [(counts, named right, answer)]
    for c in cases:
        for comp in c['components']:
            if comp.get('equivalent'):
                continue
            if comp['library']:
                pendulum = c['expected_detail'].get('pendulum', True)
                ok = _kind(comp['name'], pendulum) in named_kinds(c['expected_detail'], c['added'])
            else:      # said not explained, or (the outside alone) answered with what is the same model
                ok = not_explained(c) or c['expected'] == 'not_explained' and c['outcome'] == 'alike'
            per_effect[comp['name']].append((comp['counts'], ok, c['predicted'], c['case']))
    rates = {}
    for name, pts in sorted(per_effect.items()):
        bins = []
        for lo, hi in zip(BINS[:-1], BINS[1:]):
            hits = [ok for cnt, ok, *_ in pts if lo <= cnt < hi]
            if hits:
                bins.append(dict(lo=lo, hi=hi, n=len(hits), named=int(sum(hits)), rate=sum(hits) / len(hits)))
        above = [ok for cnt, ok, *_ in pts if cnt >= threshold]
        instead = Counter(ans for cnt, ok, ans, _ in pts if cnt >= threshold and not ok)
        rates[name] = dict(
            n=len(pts), n_above=len(above), named_above=int(sum(above)),
            rate_above=(sum(above) / len(above)) if above else None, bins=bins,
            detection_limit_counts=detection_limit([(cnt, ok) for cnt, ok, *_ in pts]),
            answered_instead=dict(instead),
            points=[dict(case=case, counts=cnt, named=ok, answer=ans) for cnt, ok, ans, case in pts])
    clean = [c for c in cases if not c['components']]
    walls = [c['wall_s'] for c in cases if c['wall_s'] is not None]
    gens = [c['generation_s'] for c in cases if c['generation_s'] is not None]
    outcomes = Counter(c['outcome'] for c in cases)
    by_setting = {}
    for key in sorted({(c['experiment'], c['theta_column']) for c in cases}):
        same = [c for c in cases if (c['experiment'], c['theta_column']) == key]
        floors = [c['oracle_counts']['x_rms_counts'] for c in same
                  if c.get('oracle_counts') and 'x_rms_counts' in c['oracle_counts']]
        by_setting[f'{key[0]} / {key[1]}'] = dict(
            n=len(same), right=sum(c['outcome'] in RIGHT for c in same),
            outcomes=dict(Counter(c['outcome'] for c in same)),
            true_model_counts_median=float(np.median(floors)) if floors else None)
    return dict(
        meta=meta, threshold_counts=threshold, n_cases=len(cases), outcomes=dict(outcomes),
        right_share=sum(outcomes[k] for k in RIGHT) / max(1, len(cases)),
        confusion={k: dict(v) for k, v in sorted(confusion.items())},
        clean=dict(n=len(clean), anything_added=sum(1 for c in clean if c['added']),
                   not_explained=sum(1 for c in clean if c['predicted'] == 'not_explained'),
                   share_anything_added=(sum(1 for c in clean if c['added']) / len(clean)) if clean else None,
                   added=dict(Counter(c['predicted'] for c in clean if c['added']))),
        per_effect=rates, by_setting=by_setting, coverage=coverage(cases),
        timing=dict(identify_wall_s_mean=float(np.mean(walls)) if walls else None,
                    identify_wall_s_median=float(np.median(walls)) if walls else None,
                    identify_wall_s_max=float(np.max(walls)) if walls else None,
                    identify_wall_s_total=float(np.sum(walls)) if walls else None,
                    generation_s_mean=float(np.mean(gens)) if gens else None,
                    generation_s_total=float(np.sum(gens)) if gens else None),
        errors=[dict(case=c['case'], rc=c['rc'], command=c['command'], stderr_tail=c['stderr_tail'])
                for c in cases if c['outcome'] == 'error'],
        cases=cases)


def targets(s: dict) -> dict:
    """The campaign's figures against its targets: the share of the cases whose every library effect
    reaches its stated detection limit (each effect's ``detection_limit_counts``; the threshold where
    none is reached) that are answered right; the share of clean cases with anything added; the cases
    of an effect from outside the library alone said 'not explained', and those under a library name."""
    limits = {name: r['detection_limit_counts'] for name, r in s['per_effect'].items()}
    above = [c for c in s['cases'] if c['expected_detail']['library'] and all(
        comp['counts'] >= (limits.get(comp['name']) or s['threshold_counts'])
        for comp in c['components'] if comp['library'])]
    outside = [c for c in s['cases'] if c['expected'] == 'not_explained']
    return dict(
        above_limit=len(above), right_above_limit=sum(c['outcome'] in ('correct', 'alike') for c in above),
        right_share_above_limit=(sum(c['outcome'] in ('correct', 'alike') for c in above) / len(above))
        if above else None,
        clean_share_anything_added=s['clean']['share_anything_added'],
        outside=len(outside), outside_not_explained=sum(map(not_explained, outside)),
        outside_same_model=sum(c['outcome'] == 'alike' for c in outside),
        outside_under_library_name=sum(bool(c['added']) and c['outcome'] not in ('alike', 'correct') for c in outside))


def _fmt(v, nd=3):
    return '-' if v is None else (f'{v:.{nd}g}' if isinstance(v, float) else str(v))


def write_markdown(s: dict, path: Path) -> None:
    tg = targets(s)
    L = [f'# Identification campaign: {s["n_cases"]} cases, seed {s["meta"].get("seed")}, code '
         f'{s["meta"].get("commit", "unknown")}', '',
         f'Threshold {s["threshold_counts"]:g} counts RMS (an effect at or above it must be named). '
         f'Right (correct, alike or acceptable): {100 * s["right_share"]:.0f} %. Outcomes: '
         + ', '.join(f'{k} {v}' for k, v in sorted(s['outcomes'].items())) + '.', '',
         f'Against the targets: right {tg["right_above_limit"]} of {tg["above_limit"]} cases whose library effects '
         f'reach their detection limits; clean cases with anything added: '
         f'{_fmt(None if tg["clean_share_anything_added"] is None else 100 * tg["clean_share_anything_added"])} %; '
         f'effects from outside the library alone: {tg["outside_not_explained"]} of {tg["outside"]} said not '
         f'explained, {tg["outside_same_model"]} answered with the corrections that are the same model (a wrong '
         f'pendulum mass: M and alpha by one factor), {tg["outside_under_library_name"]} under a library name.', '']
    cols = sorted({p for row in s['confusion'].values() for p in row})
    L += ['## Confusion matrix (rows: truth, columns: answer)', '',
          '| truth \\ answer | ' + ' | '.join(cols) + ' | n |', '|---' * (len(cols) + 2) + '|']
    for row, cnt in s['confusion'].items():
        L.append(f'| **{row}** | ' + ' | '.join(str(cnt.get(c, '')) for c in cols) + f' | {sum(cnt.values())} |')
    cl = s['clean']
    L += ['', f'Clean cases: {cl["n"]}, with anything added: {cl["anything_added"]} '
          f'({_fmt(None if cl["share_anything_added"] is None else 100 * cl["share_anything_added"])} %) '
          f'{cl["added"] or ""}; declared not explained: {cl["not_explained"]}.', '',
          '## Per effect', '',
          '| effect | cases | at/above threshold | named (above) | detection limit [counts] '
          '| answered instead (above) |',
          '|---|---|---|---|---|---|']
    for name, r in s['per_effect'].items():
        L.append(f'| {name} | {r["n"]} | {r["n_above"]} | {r["named_above"]} | '
                 f'{_fmt(r["detection_limit_counts"]) if r["detection_limit_counts"] is not None else "not reached"} | '
                 + ', '.join(f'{k} {v}' for k, v in r['answered_instead'].items()) + ' |')
    L += ['', 'Detection rate against contribution (counts RMS; named / cases per bin):', '']
    for name, r in s['per_effect'].items():
        L.append(f'- {name}: ' + '; '.join(f'[{b["lo"]:g}, {b["hi"]:g}) {b["named"]}/{b["n"]}' for b in r['bins']))
    L += ['', '## By experiment and angle column', '',
          "True model: median over the cases of the identification's validation error of the true model "
          '(the floor its ladder could reach).', '',
          '| experiment / theta column | cases | right | outcomes | true model [counts], median |',
          '|---|---|---|---|---|']
    for k, v in s['by_setting'].items():
        L.append(f'| {k} | {v["n"]} | {v["right"]} | ' + ', '.join(f'{a} {b}' for a, b in sorted(v['outcomes'].items()))
                 + f' | {_fmt(v["true_model_counts_median"])} |')
    if s.get('coverage'):
        L += ['', '## Standard errors against the truth (clean cases)', '',
              f'The final friction levels of the {LAW} law off the truth in their reported standard errors: '
              f'honest normal errors give a median |z| of 0.67 and 95 % within {COVERED:g} of them.', '',
              '| experiment | levels | median abs(z) | within 2 std |', '|---|---|---|---|']
        for k, v in s['coverage'].items():
            L.append(f'| {k} | {v["n"]} | {v["median_abs_z"]:.2f} | {100 * v["within"]:.0f} % |')
    t = s['timing']
    L += ['', '## Time', '',
          f'Identification wall time per case: mean {_fmt(t["identify_wall_s_mean"])} s, median '
          f'{_fmt(t["identify_wall_s_median"])} s, max {_fmt(t["identify_wall_s_max"])} s, total '
          f'{_fmt(t["identify_wall_s_total"])} s. Generation per case: mean {_fmt(t["generation_s_mean"])} s.', '']
    if s['errors']:
        L += ['## Identification errors', '']
        for e in s['errors']:
            L.append(f'- {e["case"]} (exit {e["rc"]}): `{e["command"]}`: ' + ' / '.join(e['stderr_tail']))
        L.append('')
    L += ['## Cases', '',
          "Validation simulation error in the identification's metric (cart counts RMS); true model: the "
          'same metric for the true constants, friction and library effects (an outside effect left out), '
          'the best the ladder could reach.', '',
          '| case | experiment | theta | Ts [ms] | truth (counts) | expected | answer | outcome | '
          'validation counts (declared -> refit -> final) | true model | wall [s] |', '|---' * 11 + '|']
    for c in s['cases']:
        comp = ', '.join(f'{x["name"]} {x["counts"]:.3g}' for x in c['components']) or 'clean'
        val = ' -> '.join(f'{v:.3g}' for _, v in c['validation_counts'])
        orc = c.get('oracle_counts') or {}
        orc_s = 'refused' if 'error' in orc else _fmt(orc.get('x_rms_counts'))
        L.append(f'| {c["case"]} | {c["experiment"]} | {c["theta_column"]} | {1e3 * c["sample_period_s"]:.3g} | '
                 f'{comp} | {c["expected"]} | {c["predicted"]} | {c["outcome"]} | {val} | {orc_s} | '
                 f'{_fmt(c["wall_s"])} |')
    path.write_text('\n'.join(L) + '\n')


def plot(s: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    names = list(s['per_effect'])
    if not names:
        return
    ncol = 3
    nrow = math.ceil(len(names) / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(4.2 * ncol, 3.0 * nrow), squeeze=False)
    rng = np.random.default_rng(0)
    for ax, name in zip(axes.flat, names):
        r = s['per_effect'][name]
        x = np.array([max(p['counts'], 1e-2) for p in r['points']])
        y = np.array([1.0 if p['named'] else 0.0 for p in r['points']])
        ax.scatter(x, y + rng.uniform(-0.04, 0.04, y.size), s=14, alpha=0.6, color='tab:blue', label='case')
        bx = [math.sqrt(max(b['lo'], 1e-2) * (b['hi'] if math.isfinite(b['hi']) else 3 * b['lo'])) for b in r['bins']]
        ax.plot(bx, [b['rate'] for b in r['bins']], 'o-', color='tab:red', label='rate per bin')
        ax.axvline(s['threshold_counts'], color='grey', ls='--', lw=1)
        if r['detection_limit_counts'] is not None:
            ax.axvline(r['detection_limit_counts'], color='tab:green', ls=':', lw=1.5, label='95 % limit')
        ax.set_xscale('log')
        ax.set_ylim(-0.1, 1.1)
        ax.set_title(f'{name} ({r["n"]} cases)', fontsize=10)
        ax.set_xlabel('contribution [counts RMS]')
        ax.set_ylabel('named right' if name not in OUTSIDE else '"not explained"')
    for ax in list(axes.flat)[len(names):]:
        ax.axis('off')
    axes.flat[0].legend(fontsize=7, loc='center right')
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_summary(out_dir: Path, cases: list[dict], threshold: float, meta: dict) -> dict:
    s = summarize(cases, threshold, meta)
    (out_dir / 'summary.json').write_text(json.dumps(s, indent=1, default=str))
    write_markdown(s, out_dir / 'summary.md')
    plot(s, out_dir / 'detection.png')
    return s


# ------------------------------------------------------------------------------------- driver
def stored_ident(case_dir: Path) -> dict:
    """A case's identification as a campaign stored it: ident/meta.json, with ident/result.json as
    ``result`` where the identification succeeded (else None)."""
    ident = json.loads((case_dir / 'ident' / 'meta.json').read_text())
    res = case_dir / 'ident' / 'result.json'
    ident['result'] = json.loads(res.read_text()) if ident.get('rc') == 0 and res.exists() else None
    return ident


def done_cases(out_dir: Path, seed: int, commit: str) -> set[str]:
    """The cases of ``out_dir`` already identified by the code of ``commit`` from the draw of ``seed`` (what
    --resume keeps). A directory of another seed, or cases of another code, is refused: one summary is one
    code's answers to one draw."""
    manifest = out_dir / 'cases' / 'manifest.json'
    if not manifest.exists():
        return set()
    old_seed = json.loads(manifest.read_text()).get('seed')
    if old_seed != seed:
        raise SystemExit(f'--resume: {out_dir} holds the draw of seed {old_seed}, not {seed}')
    done = set()
    for meta_p in sorted((out_dir / 'cases').glob('case*/ident/meta.json')):
        meta = json.loads(meta_p.read_text())
        if isinstance(meta.get('rc'), int) and meta['rc'] < 0:
            continue                    # killed by a signal (the campaign stopped): identified again
        ran = meta.get('commit')
        if ran != commit or commit.endswith('+dirty'):
            raise SystemExit(f'--resume: {meta_p.parent.parent.name} was identified by code {ran}, this tree is '
                             f'{commit} (commit the changes, or start another --out)')
        done.add(meta_p.parent.parent.name)
    return done


def run_campaign(out_dir, n_cases, seed, workers=1, progress=None, threshold=THRESHOLD, indices=None,
                 timeout=TIMEOUT, generate_workers=None, with_oracle=True, resume=False, duration=None) -> dict:
    """Generate cases (seed, i), identify each (``workers`` identifications at a time, each batch of
    ``workers`` cases generated just before it is identified), score;
    returns the summary (also written to out_dir/summary.json, summary.md, detection.png).
    ``with_oracle``: also the identification's error of the true model on each case (:func:`oracle`).
    ``resume``: keep the cases already identified in ``out_dir`` by this code (:func:`done_cases`) and
    generate and identify only the others (a campaign of hundreds of cases goes on after a stop). With
    several workers each identification's simulations share the cores among them (NUMBA_NUM_THREADS).
    ``duration`` [s]: every case this long instead of its drawn length (a quick check that the campaign runs)."""
    out_dir = Path(out_dir)
    threads = max(1, (os.cpu_count() or 1) // workers) if workers > 1 else None
    case_root = out_dir / 'cases'
    indices = list(range(n_cases)) if indices is None else list(indices)
    say = progress or (lambda msg: None)
    commit = code_commit()
    done = done_cases(out_dir, seed, commit) if resume else set()
    manifest = (json.loads((case_root / 'manifest.json').read_text()) if done
                else {'generation_s': {}, 'cases': {}})
    todo = [i for i in indices if campaign.case_name(i) not in done]
    if done:
        say(f'resumed: {len(done)} cases already identified by {commit}, {len(todo)} to go')
    t0 = time.perf_counter()
    gen_wall = 0.0

    def generated(batch: list[int]) -> None:
        """Generate the cases ``batch`` and fold them into the manifest (written at once: a stop keeps them)."""
        nonlocal manifest, gen_wall
        t = time.perf_counter()
        m = campaign.generate(case_root, len(batch), seed, batch, min(generate_workers or workers, len(batch)),
                              lambda case, sec: say(f'generated {case} in {sec:.1f} s'), duration)
        gen_wall += time.perf_counter() - t
        manifest = dict(m, indices=sorted(set(manifest.get('indices', [])) | set(batch)),
                        generation_s={**manifest['generation_s'], **m['generation_s']},
                        cases={**manifest['cases'], **m['cases']})
        (case_root / 'manifest.json').write_text(json.dumps(manifest, indent=1, sort_keys=True))
    names = [campaign.case_name(i) for i in indices]

    def one(name):
        d = case_root / name
        truth = json.loads((d / 'truth.json').read_text())
        if name in done:
            ident = stored_ident(d)
            return score_case(truth, ident, threshold, manifest['generation_s'].get(name), ident.get('oracle_counts'),
                              data_digest(d))
        if code_commit() != commit:     # the tree changed under the campaign: its answers would be two codes'
            raise SystemExit(f'{name}: the code changed from {commit} to {code_commit()} during the campaign '
                             '(run it from a worktree of one commit)')
        ident = identify_case(d, truth, timeout, threads)
        orc = oracle(d, truth) if with_oracle else None
        tmp = d / 'ident' / 'meta.json.tmp'         # written whole or not at all: a stop never leaves half a file
        tmp.write_text(json.dumps(dict({k: v for k, v in ident.items() if k != 'result'}, oracle_counts=orc,
                                       commit=commit)))
        os.replace(tmp, d / 'ident' / 'meta.json')
        return score_case(truth, ident, threshold, manifest['generation_s'].get(name), orc, data_digest(d))

    # a batch of ``workers`` cases at a time, generated then identified: a stop keeps every case done so far
    cases = []
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(workers) as ex:
        for at in range(0, len(indices), workers):
            batch = indices[at:at + workers]
            fresh = [i for i in batch if i in todo]
            if fresh:
                generated(fresh)
            for c in ex.map(one, names[at:at + workers]):
                cases.append(c)
                say(f'{c["case"]}: expected {c["expected"]}, answer {c["predicted"]} ({c["outcome"]}), {c["wall_s"]} s')
    meta = dict(seed=seed, indices=indices, workers=workers, commit=commit, resumed_cases=len(done & set(names)),
                generation_wall_s=round(gen_wall, 1),
                total_wall_s=round(time.perf_counter() - t0, 1),
                date_utc=time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime()),
                load_average_at_end=os.getloadavg(), machine=machine())
    return write_summary(out_dir, cases, threshold, meta)


def scored(out_dir, threshold=THRESHOLD, with_oracle=False) -> tuple[list[dict], dict]:
    """The cases of a campaign directory scored again, and its meta (seed, commit): of its summary, or of
    its manifest and the cases' own records where it stopped before writing one. ``with_oracle``:
    compute the true model's error where it is missing."""
    out_dir = Path(out_dir)
    cases = []
    gen = {}
    if (out_dir / 'cases' / 'manifest.json').exists():
        gen = json.loads((out_dir / 'cases' / 'manifest.json').read_text()).get('generation_s', {})
    for d in sorted((out_dir / 'cases').glob('case*')):
        truth = json.loads((d / 'truth.json').read_text())
        meta_p = d / 'ident' / 'meta.json'
        if not meta_p.exists():
            continue
        ident = stored_ident(d)
        orc = ident.get('oracle_counts')
        if orc is None and with_oracle:
            orc = oracle(d, truth)
            meta_p.write_text(json.dumps(dict({k: v for k, v in ident.items() if k != 'result'}, oracle_counts=orc)))
        cases.append(score_case(truth, ident, threshold, gen.get(d.name), orc, data_digest(d)))
    old = {}
    if (out_dir / 'summary.json').exists():
        old = json.loads((out_dir / 'summary.json').read_text()).get('meta', {})
    elif (out_dir / 'cases' / 'manifest.json').exists():      # a campaign stopped before its summary
        seed = json.loads((out_dir / 'cases' / 'manifest.json').read_text()).get('seed')
        commits = sorted({json.loads(p.read_text()).get('commit') or 'unknown'
                          for p in (out_dir / 'cases').glob('case*/ident/meta.json')})
        old = dict(seed=seed, commit=', '.join(commits))
    return cases, old


def rescore(out_dir, threshold=THRESHOLD, with_oracle=False) -> dict:
    """Score the identifications already in out_dir again (another threshold, a changed scorer);
    ``with_oracle``: compute the true model's error where it is missing."""
    cases, old = scored(out_dir, threshold, with_oracle)
    return write_summary(Path(out_dir), cases, threshold, dict(old, rescored=True))


def part_rows(src: Path, threshold=THRESHOLD) -> tuple[list[dict], dict]:
    """The scored cases and the meta of one part of a campaign: a campaign directory (scored again) or a
    summary.json (its scored cases, kept: a part whose cases are gone, e.g. one kept in bench/campaign/)."""
    if src.is_dir():
        return scored(src, threshold)
    if src.is_file():
        s = json.loads(src.read_text())
        if s.get('threshold_counts') != threshold:
            raise SystemExit(f'{src} was scored at {s.get("threshold_counts")} counts, not {threshold}')
        return s['cases'], s.get('meta', {})
    raise SystemExit(f'{src} is neither a campaign directory nor a summary.json')


def not_held(indices, parts, seed, threshold=THRESHOLD) -> list[int]:
    """The case ``indices`` that none of ``parts`` (directories or summary.json of this seed, identified by
    this tree's code) holds: what a campaign kept in parts still has to run (--except)."""
    left = list(indices)
    for part in map(Path, parts):
        rows, meta = part_rows(part, threshold)
        if meta.get('seed') != seed:
            raise SystemExit(f'--except: {part} holds the draw of seed {meta.get("seed")}, not {seed}')
        if meta.get('commit') != code_commit():
            raise SystemExit(f'--except: {part} holds the answers of code {meta.get("commit")}, this tree is '
                             f'{code_commit()} (its parts would not merge)')
        held = {c['case'] for c in rows}
        left = [i for i in left if campaign.case_name(i) not in held]
    return left


def machines_of(metas) -> list:
    """The machines the parts of ``metas`` ran on (a part's ``machine``, a merge's ``machines``), each once."""
    out: list = []
    for meta in metas:
        out += [m for m in meta.get('machines', [meta.get('machine')]) if m and m not in out]
    return out


def merge(out_dir, sources, threshold=THRESHOLD) -> dict:
    """One summary of the cases of several parts of one campaign: each source a campaign directory
    (scored again) or a summary.json (its scored cases, kept: a part whose cases are gone). The parts
    must be one seed's draw identified by one code, scored at ``threshold``, each case in one part only."""
    cases: dict[str, dict] = {}
    seeds, commits, metas = set(), set(), []
    for src in map(Path, sources):
        rows, meta = part_rows(src, threshold)
        seeds.add(meta.get('seed'))
        commits.add(meta.get('commit'))
        metas.append(meta)
        for c in rows:
            if c['case'] in cases:
                raise SystemExit(f'--merge: {c["case"]} is in two parts (the second: {src})')
            cases[c['case']] = c
    if len(seeds) > 1 or len(commits) > 1:
        raise SystemExit(f'--merge: the parts are seeds {sorted(map(str, seeds))} and codes '
                         f'{sorted(map(str, commits))}; one summary is one code\'s answers to one draw')
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    meta = dict(seed=seeds.pop(), commit=commits.pop(), merged=[str(s) for s in sources],
                machines=machines_of(metas))      # where known: a balancing loop's draw is its machine's (data_digest)
    return write_summary(out_dir, [cases[k] for k in sorted(cases)], threshold, meta)


def commit_time(commit: str) -> int:
    """The commit time [s since 1970] of ``commit`` in this repository (a part's code)."""
    try:
        return int(subprocess.run(['git', 'log', '-1', '--format=%ct', commit], cwd=ROOT, capture_output=True,
                                  text=True, check=True).stdout.strip())
    except (OSError, subprocess.CalledProcessError, ValueError):
        raise SystemExit(f'--newest: the code {commit!r} of a part is not a commit of this repository') from None


def newest(out_dir, sources, threshold=THRESHOLD) -> dict:
    """One summary of each case's newest answer over parts of one seed's draw identified by several codes:
    the parts taken in the order of their code's commit time, a case's row from the last part that holds it
    (what the campaign's code answers today where it was run again, its older code's answer where not)."""
    parts = []
    for src in map(Path, sources):
        rows, meta = part_rows(src, threshold)
        commit = str(meta.get('commit', ''))
        if not commit or commit.endswith('+dirty') or commit == 'unknown':
            raise SystemExit(f'--newest: {src} holds the answers of code {commit!r}, not of a commit')
        parts.append((commit_time(commit), str(src), rows, meta))
    parts.sort(key=lambda q: q[:2])
    seeds = {meta.get('seed') for *_, meta in parts}
    if len(seeds) != 1:
        raise SystemExit(f'--newest: the parts are draws of seeds {sorted(map(str, seeds))}; one summary is one draw')
    cases = {c['case']: dict(c, code=meta['commit']) for *_, rows, meta in parts for c in rows}
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    meta = dict(seed=seeds.pop(), commit='newest of ' + ', '.join(m['commit'] for *_, m in parts),
                newest=[src for _, src, _, _ in parts], machines=machines_of(m for *_, m in parts))
    return write_summary(out_dir, [cases[k] for k in sorted(cases)], threshold, meta)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--out', required=True)
    ap.add_argument('--cases', type=int, default=40)
    ap.add_argument('--seed', type=int, default=1)
    ap.add_argument('--indices', help='comma-separated case indices instead of 0..N-1')
    ap.add_argument('--threshold', type=float, default=THRESHOLD, help='counts RMS (default %(default)s)')
    ap.add_argument('--workers', type=int, default=1, help='identifications at a time (default 1)')
    ap.add_argument('--timeout', type=float, default=TIMEOUT, help='seconds per identification')
    ap.add_argument('--rescore', action='store_true', help='score the results already in --out')
    ap.add_argument('--no-oracle', action='store_true', help="skip the true model's error per case")
    ap.add_argument('--resume', action='store_true',
                    help='keep the cases --out already holds from this seed and this code; identify the rest')
    ap.add_argument('--merge', nargs='+', metavar='PART',
                    help='write one summary into --out of these parts of one campaign (directories or summary.json)')
    ap.add_argument('--except', dest='skip', nargs='+', metavar='PART', default=[],
                    help='leave out the cases these parts (directories or summary.json) already hold: a campaign '
                         'kept in bench/campaign/ goes on with the rest')
    ap.add_argument('--newest', nargs='+', metavar='PART',
                    help="write one summary into --out of each case's newest answer over these parts of one draw "
                         "(directories or summary.json; their codes ordered by commit time)")
    a = ap.parse_args(argv)
    if a.merge:
        s = merge(a.out, a.merge, a.threshold)
    elif a.newest:
        s = newest(a.out, a.newest, a.threshold)
    elif a.rescore:
        s = rescore(a.out, a.threshold, not a.no_oracle)
    else:
        idx = [int(i) for i in a.indices.split(',')] if a.indices else list(range(a.cases))
        idx = not_held(idx, a.skip, a.seed, a.threshold)
        s = run_campaign(a.out, a.cases, a.seed, a.workers, lambda m: print(m, flush=True), a.threshold, idx,
                         a.timeout, with_oracle=not a.no_oracle, resume=a.resume)
    print(Path(a.out) / 'summary.md')
    print(json.dumps({k: s[k] for k in ('outcomes', 'confusion', 'clean', 'timing')}, indent=1))
    return 0


if __name__ == '__main__':
    sys.exit(main())
