"""Design check of a gain on a scenario: the hunting to expect, the delay the loop takes, what
the encoders leave, and how each moves with the friction (``./ipfric design --check``).

Each case is the scenario's loop with one friction (the scenario's, scaled down and up, or
moved by an identification's standard errors); for each:

- **Hunting**: the periodic orbit of the sampled loop (:func:`orbit.find_orbit`, from the
  scenario's start), with exact sensors and with the scenario's encoders. Where Newton finds
  no orbit (the encoders make the cycle irregular), the cycle a run settles into
  (:func:`settled_cycle`). Beside it the describing-function estimate
  (:func:`describing.predict_hunting`: sliding through v = 0, exact sensors).
- **Linear critical delay** tau_c, eq. (27), of two linearizations at the upright: sgn(v)
  smoothed by tanh(delta v) (the paper's, section 3.1; 0 when the upright is unstable
  without delay) and the sliding cart, c = beta + eps (the describing function's linear part).
- **Effective critical delay**: the largest delay for which a run from the scenario's start
  still holds the pendulum (no fall, no track limit in :data:`HOLD_SECONDS`), scanned in
  steps from 0 and bisected above the scenario's delay; and the delay from which the
  hunting has grown :data:`GROWTH` times past its size at the scenario's delay.
- **Encoder floor**: the cycle left with the scenario's encoders when the friction law is
  made viscous only (static and Coulomb levels removed, eps kept, plant_truth kept): what
  quantization alone makes the loop do. Defined only when that loop rests with exact sensors
  (else the delay or the gain, not quantization, keep it moving).

Each case is a :class:`CheckCase` of physics specs (:func:`case_of` makes one from a scenario);
:func:`check_scenarios` checks a scenario against friction variants of it (:func:`friction_cases`).
"""
from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import partial

import numpy as np

from ..design.critical_delay import gain_critical_delay
from ..design.describing import friction_loop, predict_hunting
from ..design.linearize import jacobian
from ..physics.controller import FeedbackSpec
from ..physics.params import FrictionParams, PlantParams
from ..physics.rig import RigSpec
from ..run.scenario import Scenario
from .orbit import LoopNumbers, OrbitError, find_orbit, loop_numbers, settle
from .variants import exact_sensors, scenario_at

__all__ = ['MAX_DELAY', 'linear_delays', 'friction_cases', 'check_scenarios']

#: the loops of a case: exact sensors, the scenario's encoders, and on viscous-only friction exact sensors
#: and the encoders
LOOPS = ('exact', 'encoders', 'viscous', 'floor')
#: simulated seconds a run from the start must last to hold the pendulum; its last third sets the section
HOLD_SECONDS = 60.0
#: full cycles a settled cycle is measured over (after HOLD_SECONDS), and in a delay scan
CYCLES = 8
SCAN_CYCLES = 3
#: a run's cycles repeat every m returns (m <= MAX_CROSSINGS) when their lengths agree to REPEAT_SAMPLES;
#: only then is an orbit looked for (an irregular cycle has none to converge to)
MAX_CROSSINGS = 4
REPEAT_SAMPLES = 2
#: frequency grid of the linear tau_c (points up to 200 rad/s; each crossing is then refined)
TAU_C_GRID = 5000
#: cart peak-to-peak [m] under which a loop rests
REST_M = 1e-6
#: the hunting has grown once its cart peak-to-peak exceeds GROWTH times that at the scenario's delay
GROWTH = 2.0
#: the delay scan [s]: step, default end, bisection tolerance
DELAY_STEP = 0.005
MAX_DELAY = 0.2
DELAY_TOL = 5e-4
#: the numbers compared across cases: key, what, unit shown, factor from SI
NUMBERS = (
    ('x_p2p_exact_m', 'hunting, cart p2p, exact sensors', 'cm', 100.0),
    ('period_exact_s', 'hunting period, exact sensors', 's', 1.0),
    ('theta_p2p_exact_rad', 'hunting, angle p2p, exact sensors', 'deg', 180.0 / math.pi),
    ('stuck_exact', 'time stuck, exact sensors', '%', 100.0),
    ('x_p2p_encoders_m', 'hunting, cart p2p, encoders', 'cm', 100.0),
    ('period_encoders_s', 'hunting period, encoders', 's', 1.0),
    ('x_p2p_describing_m', 'describing function, cart p2p', 'cm', 100.0),
    ('period_describing_s', 'describing function, period', 's', 1.0),
    ('tau_c_sliding_s', 'linear tau_c, sliding (c = beta + eps)', 'ms', 1e3),
    ('tau_c_tanh_s', 'linear tau_c, tanh(delta v)', 'ms', 1e3),
    ('holds_to_exact_s', 'holds the pendulum up to, exact sensors', 'ms', 1e3),
    ('holds_to_encoders_s', 'holds the pendulum up to, encoders', 'ms', 1e3),
    ('small_to_exact_s', f'hunting within {GROWTH:g}x up to, exact sensors', 'ms', 1e3),
    ('floor_x_p2p_m', 'encoder floor, cart p2p', 'mm', 1e3),
    ('floor_theta_p2p_rad', 'encoder floor, angle p2p', 'deg', 180.0 / math.pi),
)


@dataclass(frozen=True)
class CheckCase:
    """One case of a check: a gain on a plant and friction, and its loops.

    ``value``: where the case sits on the sensitivity axis (a friction scale, or standard
    errors); ``gain`` [V/m, V/rad, V s/m, V s/rad], ``delay`` [s], ``cutoff_hz`` [Hz]: the
    controller's; ``rigs``: a ``Rig.loop_spec()`` for each of :data:`LOOPS`; ``feedback``:
    the controller's ``loop_spec()``.
    """

    label: str
    value: float
    plant: PlantParams
    friction: FrictionParams
    gain: tuple
    delay: float
    cutoff_hz: float
    rigs: Mapping[str, RigSpec] = field(repr=False, compare=False)
    feedback: FeedbackSpec = field(repr=False, compare=False)

    def loop(self, kind: str, delay: float | None = None) -> LoopNumbers:
        """The sampled loop ``kind`` (one of :data:`LOOPS`) at ``delay`` [s] (default: the controller's)."""
        return loop_numbers(self.rigs[kind], self.feedback, delay)


def settled_cycle(loop: LoopNumbers, transient: float = HOLD_SECONDS, cycles: int = CYCLES) -> dict:
    """What a run from the loop's start settles into.

    ``behaviour``: 'hunts', 'rests', or the limit that ended the run ('fallen', 'track_limit');
    ``holds``: the pendulum is still up. For 'hunts', over ``cycles`` rises of theta through the
    middle of its swing after ``transient`` [s]: x_p2p_m, theta_p2p_rad (true states at the
    samples), ``repeats_every`` (the smallest m <= MAX_CROSSINGS for which the cycles repeat every
    m rises to REPEAT_SAMPLES samples, else None: irregular), period_s (m times the mean time
    between rises; that mean when irregular), period_spread (std / mean of the times between
    rises), stuck_fraction.
    """
    _, _, seen = settle(loop, None, transient, cycles + 1)
    end = seen[-1].code
    if end in ('fallen', 'track_limit'):
        return {'behaviour': end, 'holds': False}
    full = [c for c in seen[1:] if c.code == 'crossing']
    x = [(c.x_center - c.x_p2p / 2, c.x_center + c.x_p2p / 2) for c in full]
    th = [(c.theta_center - c.theta_p2p / 2, c.theta_center + c.theta_p2p / 2) for c in full]
    if not full or max(b for _, b in x) - min(a for a, _ in x) < REST_M:
        return {'behaviour': 'rests', 'holds': True, 'x_p2p_m': 0.0, 'theta_p2p_rad': 0.0}
    n = np.array([c.samples for c in full])
    every = next((m for m in range(1, min(MAX_CROSSINGS, len(n) - 1) + 1)
                  if np.all(np.abs(n[m:] - n[:-m]) <= REPEAT_SAMPLES)), None)
    return {'behaviour': 'hunts', 'holds': True,
            'x_p2p_m': float(max(b for _, b in x) - min(a for a, _ in x)),
            'theta_p2p_rad': float(max(b for _, b in th) - min(a for a, _ in th)),
            'repeats_every': every, 'period_s': float((every or 1) * n.mean() * loop.dt),
            'period_spread': float(n.std() / n.mean()),
            'stuck_fraction': float(sum(c.stuck_fraction * c.samples for c in full) / n.sum()),
            'cycles': len(full)}


def hunting(loop: LoopNumbers) -> dict:
    """The hunting of a loop: ``run`` (:func:`settled_cycle`) and ``orbit`` (the orbit's summary,
    or None with ``no_orbit``: why); x_p2p_m, theta_p2p_rad, period_s, stuck_fraction and
    ``source`` ('orbit', 'run', or the run's behaviour when it does not hunt) are the orbit's
    when Newton finds one, else the run's. Newton is tried only when the run's cycles repeat."""
    run = settled_cycle(loop)
    out: dict = {'run': run, 'orbit': None}
    if run['behaviour'] == 'hunts' and run['repeats_every'] is None:
        out['no_orbit'] = (f'no orbit looked for: the run\'s cycles do not repeat (their lengths vary by '
                           f'{100 * run["period_spread"]:.0f} %)')
    elif run['behaviour'] == 'hunts':
        try:
            out['orbit'] = find_orbit(loop).summary()
        except OrbitError as exc:
            out['no_orbit'] = str(exc)
    else:
        out['no_orbit'] = f'the run {run["behaviour"].replace("_", " ")}'
    main = out['orbit'] or run
    out.update(source='orbit' if out['orbit'] else run['behaviour'] if run['behaviour'] != 'hunts' else 'run',
               **{k: main.get(k) for k in ('x_p2p_m', 'theta_p2p_rad', 'period_s', 'stuck_fraction')})
    return out


def linear_delays(plant: PlantParams, friction: FrictionParams, gain) -> dict:
    """tau_c [s] of eq. (27) for ``gain`` on the two linearizations: ``tanh`` (sgn(v) ->
    tanh(delta v), :func:`linearize.jacobian`) and ``sliding`` (c = beta + eps,
    :func:`describing.friction_loop`); each with its crossing frequency [Hz]."""
    A, B = jacobian(plant, friction)
    As, Bs, _ = friction_loop(plant, friction)
    return {'tanh': gain_critical_delay(A, B, gain, n_grid=TAU_C_GRID),
            'sliding': gain_critical_delay(As, Bs, gain, n_grid=TAU_C_GRID), 'delta': friction.delta}


def _edge(make_loop, rows, start: int, ok, tol: float, cycles: int) -> tuple[float | None, float | None]:
    """(last delay where ``ok``, first where not) above ``rows[start]``, bisected to ``tol`` [s];
    (None, delay) when not ok at ``rows[start]``, (last scanned, None) when ok throughout."""
    if not ok(rows[start]):
        return None, rows[start]['delay_s']
    bad = next((i for i in range(start + 1, len(rows)) if not ok(rows[i])), None)
    if bad is None:
        return rows[-1]['delay_s'], None
    lo, hi = rows[bad - 1]['delay_s'], rows[bad]['delay_s']
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        if ok({'delay_s': mid, **settled_cycle(make_loop(mid), cycles=cycles)}):
            lo = mid
        else:
            hi = mid
    return lo, hi


def delay_margins(make_loop: Callable[[float], LoopNumbers], delay: float, max_delay: float = MAX_DELAY,
                  step: float = DELAY_STEP, tol: float = DELAY_TOL, cycles: int = SCAN_CYCLES) -> dict:
    """The effective critical delay of a loop: runs from the start at delays 0, ``step``, ...,
    ``max_delay`` [s] and at the scenario's ``delay`` [s]; ``make_loop(d)`` gives the loop at d.

    ``holds_to_s``: the largest delay above ``delay`` that still holds the pendulum, bisected
    to ``tol`` against ``lost_from_s`` (None: lost at ``delay`` already; ``lost_from_s`` None:
    held over the whole scan); ``holds_again_s``: a scanned delay beyond the loss that holds
    again (None if none). ``small_to_s`` / ``grows_from_s``: the same edge for the hunting
    staying within :data:`GROWTH` times its cart peak-to-peak at ``delay``. ``scan``: the rows.
    """
    grid = sorted({round(float(d), 9) for d in np.arange(0.0, max_delay + 0.5 * step, step)} | {round(delay, 9)})
    rows = [{'delay_s': d, **settled_cycle(make_loop(d), cycles=cycles)} for d in grid]
    start = grid.index(round(delay, 9))
    ref = rows[start].get('x_p2p_m') or 0.0

    def holds(r):
        return r['holds']

    def small(r):
        return r['holds'] and r['x_p2p_m'] <= max(GROWTH * ref, REST_M)
    held, lost = _edge(make_loop, rows, start, holds, tol, cycles)
    within, grows = _edge(make_loop, rows, start, small, tol, cycles)
    again = next((r['delay_s'] for r in rows if lost is not None and r['delay_s'] > lost and r['holds']), None)
    return {'holds_to_s': held, 'lost_from_s': lost, 'holds_again_s': again, 'small_to_s': within,
            'grows_from_s': grows, 'reference_x_p2p_m': ref, 'max_delay_s': max_delay, 'step_s': step,
            'tolerance_s': tol, 'run_s': HOLD_SECONDS, 'scan': rows}


def describing_estimate(case: CheckCase) -> dict:
    """:func:`describing.predict_hunting` of the case, or ``intersection`` False with the reason."""
    try:
        return predict_hunting(case.plant, case.friction, case.gain, case.delay, case.cutoff_hz)
    except ValueError as exc:
        return {'intersection': False, 'reason': str(exc)}


def check_case(case: CheckCase, max_delay: float = MAX_DELAY,
               progress: Callable[[str], None] | None = None) -> dict:
    """Every number of the check for one case (see the module docstring)."""
    def say(what):
        if progress:
            progress(f'{case.label}: {what}')
    out: dict = {'label': case.label, 'value': case.value, 'friction': case.friction.to_dict(),
                 'delay_s': case.delay, 'hunting': {}, 'effective_delay': {}}
    for kind in ('exact', 'encoders'):
        say(f'hunting, {kind}')
        out['hunting'][kind] = hunting(case.loop(kind))
    say('describing function, linear tau_c')
    out['describing_function'] = describing_estimate(case)
    out['linear_critical_delay'] = linear_delays(case.plant, case.friction, case.gain)
    for kind in ('exact', 'encoders'):
        say(f'delay scan 0-{1e3 * max_delay:g} ms, {kind}')
        out['effective_delay'][kind] = delay_margins(partial(case.loop, kind), case.delay, max_delay)
    say('encoder floor')
    free = settled_cycle(case.loop('viscous'))
    out['encoder_floor'] = {**settled_cycle(case.loop('floor')), 'exact_sensors': free,
                            'defined': free['behaviour'] == 'rests'}
    out['numbers'] = case_numbers(out)
    return out


def case_numbers(c: dict) -> dict:
    """The :data:`NUMBERS` of one case's result (None where there is none)."""
    h, df, e = c['hunting'], c['describing_function'], c['effective_delay']
    tau, floor = c['linear_critical_delay'], c['encoder_floor']
    floor = floor if floor['defined'] else {}
    return {'x_p2p_exact_m': h['exact']['x_p2p_m'], 'period_exact_s': h['exact']['period_s'],
            'theta_p2p_exact_rad': h['exact']['theta_p2p_rad'], 'stuck_exact': h['exact']['stuck_fraction'],
            'x_p2p_encoders_m': h['encoders']['x_p2p_m'], 'period_encoders_s': h['encoders']['period_s'],
            'x_p2p_describing_m': df.get('x_p2p_m'), 'period_describing_s': df.get('period_s'),
            'tau_c_sliding_s': tau['sliding']['tau_c'], 'tau_c_tanh_s': tau['tanh']['tau_c'],
            'holds_to_exact_s': e['exact']['holds_to_s'], 'holds_to_encoders_s': e['encoders']['holds_to_s'],
            'small_to_exact_s': e['exact']['small_to_s'],
            'floor_x_p2p_m': floor.get('x_p2p_m'), 'floor_theta_p2p_rad': floor.get('theta_p2p_rad')}


def sensitivity(cases: Sequence[dict], nominal: int) -> list[dict]:
    """Per number of :data:`NUMBERS`: its value in each case and its change from case ``nominal``
    (relative; None where a value is missing or the nominal is 0)."""
    rows = []
    for key, what, unit, factor in NUMBERS:
        vals = [c['numbers'][key] for c in cases]
        ref = vals[nominal]
        change = [None if v is None or not ref else v / ref - 1.0 for v in vals]
        rows.append({'key': key, 'what': what, 'unit': unit, 'factor': factor, 'values': vals, 'change': change})
    return rows


def _cm(v):
    return 'none' if v is None else f'{100 * v:.2g} cm' if v < 0.01 else f'{100 * v:.1f} cm'


def _ms(v):
    return 'none' if v is None else f'{1e3 * v:.0f} ms'


def verdict(cases: Sequence[dict], nominal: int) -> str:
    """One line an engineer can act on: the nominal case's hunting, delay and floor, then what
    the other cases change."""
    c = cases[nominal]
    n, h = c['numbers'], c['hunting']
    hx = h['exact']
    if hx['source'] in ('rests', 'fallen', 'track_limit'):
        head = f'exact sensors: {hx["source"].replace("_", " ")}'
    else:
        head = f'hunts {_cm(n["x_p2p_exact_m"])} p2p at {n["period_exact_s"]:.1f} s ({hx["source"]})'
    he = h['encoders']
    enc = (f'{he["source"].replace("_", " ")} with the encoders' if he['source'] in ('rests', 'fallen', 'track_limit')
           else f'{_cm(n["x_p2p_encoders_m"])} at {n["period_encoders_s"]:.1f} s with the encoders')
    e = c['effective_delay']['exact']
    held = e['holds_to_s']
    delay = ('lost at its own delay' if held is None else
             f'holds to {_ms(held)} delay' if e['lost_from_s'] is not None else f'holds over 0-{_ms(held)} delay')
    if e['grows_from_s'] is not None and held is not None and e['grows_from_s'] < held:
        delay += (f' (starts hunting from {_ms(e["grows_from_s"])})' if not e['reference_x_p2p_m'] else
                  f' (hunting grows past {GROWTH:g}x from {_ms(e["grows_from_s"])})')
    fx, hx_p2p = n['floor_x_p2p_m'], n['x_p2p_exact_m']
    if not c['encoder_floor']['defined']:
        floor = 'no encoder floor: without Coulomb friction the loop does not rest even with exact sensors'
    else:
        floor = 'encoder floor: rests' if not fx else f'encoder floor {1e3 * fx:.1f} mm'
    if fx and hx_p2p:
        floor += (f' (the hunting is {hx_p2p / fx:.0f}x larger: friction sets it)' if hx_p2p > 3 * fx else
                  f' (the hunting is only {hx_p2p / fx:.1f}x larger: quantization sets much of it)')
    elif fx and hx['source'] == 'rests':
        floor += ' (with exact sensors the loop rests: the encoders set the hunting)'
    parts = [f'{head}, {enc}; {delay}; {floor}']
    for i, o in enumerate(cases):
        if i == nominal:
            continue
        m = o['numbers']
        parts.append(f'{o["label"]} -> ' + (f'{_cm(m["x_p2p_exact_m"])} at {m["period_exact_s"]:.1f} s'
                                            if m['x_p2p_exact_m'] and m['period_exact_s'] else
                                            o['hunting']['exact']['source'].replace('_', ' '))
                     + f', holds to {_ms(m["holds_to_exact_s"])}')
    return '; '.join(parts)


def design_check(nominal: CheckCase, others: Sequence[CheckCase], max_delay: float = MAX_DELAY,
                 progress: Callable[[str], None] | None = None) -> dict:
    """The check of ``nominal`` and its sensitivity over ``others``: ``cases`` (sorted by value,
    :func:`check_case` each), ``nominal`` (its index), ``sensitivity``, ``verdict``."""
    if not (math.isfinite(max_delay) and max_delay > 0):
        raise ValueError(f'max_delay = {max_delay!r} s: must be > 0')
    order = sorted([nominal, *others], key=lambda c: c.value)
    cases = [check_case(c, max_delay, progress) for c in order]
    i = next(k for k, c in enumerate(order) if c is nominal)
    return {'cases': cases, 'nominal': i, 'gain': list(nominal.gain), 'delay_s': nominal.delay,
            'cutoff_hz': nominal.cutoff_hz, 'sensitivity': sensitivity(cases, i), 'verdict': verdict(cases, i),
            'definitions': {'hold_seconds': HOLD_SECONDS, 'cycles': CYCLES, 'scan_cycles': SCAN_CYCLES,
                            'growth': GROWTH, 'rest_m': REST_M}}


def case_of(scn: Scenario, label: str, value: float) -> CheckCase:
    """The check's view of scenario ``scn``: its physics and its loops (:data:`LOOPS`)."""
    viscous = replace(scn, friction=scn.friction.replace(model='viscous', smoothing='none'))
    rigs = {'exact': exact_sensors(scn), 'encoders': scn, 'viscous': exact_sensors(viscous), 'floor': viscous}
    c = scn.controller
    return CheckCase(label, value, scn.plant, scn.friction, tuple(scn.gain()), c.delay, c.cutoff_hz,
                     {k: v.make_rig().loop_spec() for k, v in rigs.items()}, scn.make_controller().loop_spec())


def friction_cases(base: Scenario, change: float = 0.3) -> tuple[list[tuple[str, float, Scenario]], str]:
    """The friction cases of a check: (label, value, scenario) at friction x(1 - ``change``), the scenario,
    x(1 + ``change``) (mu_s, mu_c and eps scaled), and the axis they lie on."""
    if not (math.isfinite(change) and 0.0 < change < 1.0):
        raise ValueError(f'--friction-change: {change!r} must be in (0, 1) (0.3 = friction x0.7 and x1.3)')
    lo, hi = 1.0 - change, 1.0 + change
    return ([(f'friction x{lo:g}', lo, scenario_at(base, 'friction', lo)), ('scenario', 1.0, base),
             (f'friction x{hi:g}', hi, scenario_at(base, 'friction', hi))], 'friction scale (mu_s, mu_c, eps)')


def check_scenarios(base: Scenario, scenarios: Sequence[tuple[str, float, Scenario]], axis: str,
                    max_delay: float = MAX_DELAY, progress: Callable[[str], None] | None = None) -> dict:
    """:func:`design_check` of the middle of ``scenarios`` (label, value, scenario: three, sorted by value)
    against the other two, with the scenario's encoders and sample period."""
    if not (math.isfinite(max_delay) and 0.0 < max_delay <= 1.0):
        raise ValueError(f'--max-delay: {max_delay!r} s must be in (0, 1] s')
    if max_delay <= base.controller.delay:
        raise ValueError(f'--max-delay: {max_delay:g} s must exceed the scenario\'s delay '
                         f'({base.controller.delay:g} s)')
    t0 = time.perf_counter()
    cases = [case_of(scn, label, value) for label, value, scn in scenarios]
    res = design_check(cases[1], [cases[0], cases[2]], max_delay, progress)
    res.update(axis=axis, encoders={'cart_m': base.sim.cart_resolution, 'angle_rad': base.sim.angle_resolution},
               sample_period_s=base.sample_period, seconds=round(time.perf_counter() - t0, 1))
    return res
