"""What ``./ipfric orbit`` computes about a scenario's loop and writes: its periodic orbits at one
delay (the stable one a run settles on and the unstable partners inside it), the edge of the
upright's basin with the unstable orbit on it, a plain run beside them, and the branches of
orbits traced over a parameter by continuation with their bifurcation diagram.

Files in the output directory: ``orbit.json`` (every number), with a continuation also
``branches.csv`` (one row per orbit) and ``bifurcation.png``.
"""
from __future__ import annotations

import csv
import json
import math
import time
from collections.abc import Callable
from contextlib import nullcontext
from pathlib import Path

from ..design.describing import hunting_over_delays, hunting_over_gain_scales
from ..physics.params import ConfigError, check_number
from ..run.scenario import CONTROLLER_FIELDS, Scenario
from .basin import Edge, basin_edge, shape_threshold
from .bifurcation import diagram
from .continuation import parse_continuation, trace, unstable_partners
from .executor import make_executor, scheduler_address
from .orbit import OrbitError, find_orbit, simulated_cycle
from .variants import PARAMETERS, loop_of, scenario_at

__all__ = ['DIAGRAM_SIMULATIONS', 'MAX_RUN_SAMPLES', 'check_run_length', 'orbit_delay', 'continuation_of',
           'basin_bracket', 'orbits_at', 'basin_of', 'continuation_study', 'orbit_study']

#: simulations from the start drawn beside the branches of a diagram, evenly over its range
DIAGRAM_SIMULATIONS = 29
#: the most samples one simulated run (``--simulate``, a ``--basin`` run) may take: 2e6 (2000 s at 1 kHz)
MAX_RUN_SAMPLES = 2_000_000


def check_run_length(option: str, seconds: float, base: Scenario, zero: bool = False) -> float:
    """``seconds`` of a simulated run, checked: finite, > 0 (or 0 with ``zero``), at most
    :data:`MAX_RUN_SAMPLES` samples of ``base``'s loop."""
    longest = MAX_RUN_SAMPLES * base.sample_period
    low = '0' if zero else '0 (exclusive)'
    if not (math.isfinite(seconds) and (seconds >= 0 if zero else seconds > 0) and seconds <= longest):
        raise ConfigError(f'{option}: {seconds!r} s is out of range; allowed {low} .. {longest:g} s '
                          f'({MAX_RUN_SAMPLES} samples at {1 / base.sample_period:g} Hz)')
    return seconds


def orbit_delay(base: Scenario, delay: float | None) -> tuple[float, Scenario]:
    """The feedback delay [s] the orbits are solved at (``delay`` or the scenario's; it may fall between
    samples), and the scenario runs are made with (the delay rounded to whole samples)."""
    if delay is None:
        return base.controller.delay, base
    check_number('--delay', delay, CONTROLLER_FIELDS['delay'])
    return delay, scenario_at(base, 'delay', delay)


def continuation_of(text: str) -> tuple[str, float, float, int]:
    """(parameter, start, stop, points) of ``--continue NAME=START:STOP[:POINTS]``, checked."""
    try:
        cont = parse_continuation(text)
    except ValueError as exc:
        raise ConfigError(str(exc)) from None
    if cont[0] not in PARAMETERS:
        raise ConfigError(f'--continue {cont[0]!r}: unknown parameter; allowed: {", ".join(PARAMETERS)} '
                          '(delay [s]; gain and friction as multiples of the scenario\'s)')
    if cont[0] == 'delay':
        spec = CONTROLLER_FIELDS['delay']
        if min(cont[1:3]) < spec.lo or max(cont[1:3]) > spec.hi:
            raise ConfigError(f'--continue {text!r}: delays out of range; allowed {spec.describe()}')
    if cont[0] == 'friction' and min(cont[1:3]) < 0:
        raise ConfigError(f'--continue {text!r}: a negative friction scale; allowed >= 0 (multiples of the '
                          'scenario\'s mu_s, mu_c, eps)')
    return cont


def basin_bracket(text: str, duration: float) -> tuple[float, float]:
    """(LO, HI) [rad] of ``--basin LO,HI``, checked with the longest run ``duration`` [s]."""
    try:
        lo, hi = (float(v) for v in text.split(','))
    except ValueError:
        raise ConfigError(f'--basin: {text!r}: expected LO,HI in rad, e.g. 1e-4,0.05') from None
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 <= lo < hi):
        raise ConfigError(f'--basin: need finite 0 <= LO < HI [rad], got {text!r}')
    if not (math.isfinite(duration) and duration > 0):
        raise ConfigError(f'--duration: {duration!r} must be a positive number of seconds')
    return lo, hi


def orbits_at(base: Scenario, delay: float) -> dict:
    """The periodic orbits of ``base``'s loop at ``delay`` [s]: the one a run settles on and its unstable
    partners (``orbits``, summaries), or why there is none (``no_orbit``), and the seconds it took."""
    t0 = time.perf_counter()
    loop = loop_of(base, 'delay', delay)
    res: dict = {'delay_s': delay}
    try:
        main_orbit = find_orbit(loop)
        orbits = [main_orbit] + unstable_partners(loop, main_orbit)
    except OrbitError as exc:
        orbits, res['no_orbit'] = [], str(exc)
    res['orbits'] = [o.summary() for o in orbits]
    res['seconds'] = round(time.perf_counter() - t0, 3)
    return res


def basin_of(base: Scenario, delay: float, lo: float, hi: float, duration: float) -> tuple[dict, Edge]:
    """The edge of the upright's basin over theta0 in [lo, hi] [rad] and the orbit on it (summary, Edge)."""
    def loop_at(theta0):
        return loop_of(base, 'theta0', theta0, delay)
    try:
        edge = basin_edge(loop_at, lo, hi, duration=duration)
    except ValueError as exc:
        raise ConfigError(f'--basin: {exc}') from None
    out = edge.summary()
    if edge.orbit is not None:
        out['shape_threshold'] = list(shape_threshold(loop_at(edge.settles_below), edge.orbit, duration=duration))
    return out, edge


def continuation_study(base: Scenario, delay: float, cont: tuple[str, float, float, int], out: Path,
                       edge: Edge | None = None, scheduler: str | None = None, describing: bool = False,
                       plots: bool = True, progress: Callable[[str], None] | None = None) -> dict:
    """The branches of orbits over ``cont`` (:func:`continuation_of`), from the orbit on the basin's ``edge``
    too when given: ``out/branches.csv`` and, with ``plots``, ``out/bifurcation.png`` (the describing
    function's prediction on it with ``describing``, for the delay or the gain)."""
    name, start, stop, count = cont
    t0 = time.perf_counter()
    with make_executor(scheduler) if scheduler else nullcontext() as cluster:
        given = [(delay if name == 'delay' else 1.0, edge.orbit)] if edge and edge.orbit else []
        found = trace(lambda v: loop_of(base, name, v, delay), start, stop, count, progress=progress,
                      executor=cluster, orbits=given)
    res = {'parameter': name, 'range': [start, stop], 'points': len(found.points),
           'branches': len({p.branch for p in found.points}), 'events': found.events, 'probes': found.probes,
           'jacobians': found.jacobians, 'steps': found.steps, 'seconds': round(time.perf_counter() - t0, 2)}
    rows = [p.row() for p in found.points]
    with open(out / 'branches.csv', 'w', newline='') as fh:
        wr = csv.DictWriter(fh, fieldnames=list(rows[0]) if rows else ['parameter'])
        wr.writeheader()
        wr.writerows(rows)
    if plots:
        values = [start + (stop - start) * i / (DIAGRAM_SIMULATIONS - 1) for i in range(DIAGRAM_SIMULATIONS)]
        df = None
        if describing and name in ('delay', 'gain'):
            c = base.controller
            hunt = (hunting_over_delays(base.plant, base.friction, base.gain(), values, c.cutoff_hz)
                    if name == 'delay' else
                    hunting_over_gain_scales(base.plant, base.friction, base.gain(), values, c.delay, c.cutoff_hz))
            df = [{'parameter': v, 'x_p2p_m': d['x_p2p_m']} for v, d in zip(values, hunt) if d['intersection']]
            res['describing_function'] = df
        res['plot'] = str(diagram(base, name, values, rows, found.events, out / 'bifurcation.png', df))
    return res


def orbit_study(base: Scenario, out: str | Path, delay: float | None = None, basin: str | None = None,
                duration: float = 40.0, simulate: float = 120.0, cont: str | None = None,
                scheduler: str | None = None, describing: bool = False, plots: bool = True,
                progress: Callable[[str], None] | None = None, info: dict | None = None) -> dict:
    """Everything ``./ipfric orbit`` reports on ``base`` (see the module docstring), written to
    ``out/orbit.json`` after ``info``; ``basin``: 'LO,HI' [rad], ``cont``: 'NAME=START:STOP[:POINTS]'."""
    continuation = continuation_of(cont) if cont else None
    if scheduler:
        scheduler_address(scheduler)
    bracket = basin_bracket(basin, duration) if basin else None
    if bracket:
        check_run_length('--duration', duration, base)
    check_run_length('--simulate', simulate, base, zero=True)
    delay, base = orbit_delay(base, delay)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    res = {**(info or {}), **orbits_at(base, delay)}
    edge = None
    if bracket:
        res['basin'], edge = basin_of(base, delay, *bracket, duration)
    if simulate > 0:
        res['simulation'] = simulated_cycle(base.make_rig(), base.make_controller(), simulate)
        res['simulation']['delay_s'] = base.controller.delay
    if continuation:
        res['continuation'] = continuation_study(base, delay, continuation, out, edge, scheduler, describing, plots,
                                                 progress)
    (out / 'orbit.json').write_text(json.dumps(res, indent=2, default=float))
    res['files'] = {'json': str(out / 'orbit.json')}
    return res
