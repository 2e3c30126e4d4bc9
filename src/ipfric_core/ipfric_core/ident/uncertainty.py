"""The uncertainty an identification leaves: draws of the rig from its parameter table.

``./ipfric identify --out DIR`` writes ``DIR/result.json`` with the ladder's final model:
every parameter with its value and, for the fitted ones, its standard error (from the
Jacobian of the simulation error at the optimum). :func:`load_report` rebuilds that
:class:`~ipfric_core.ident.model.Model`; :func:`report_draw` draws each fitted parameter
from an independent Gaussian N(value, std^2) (the report holds standard errors, not their
covariance), clipped to the parameter's bounds, and turns the draw into the scenario's
plant, friction and ``plant_truth`` by the model's own export (the same conversion as
``--export``). Parameters without a finite standard error keep their value.
"""
from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import replace
from functools import partial
from pathlib import Path

import numpy as np

from ..physics.params import FRICTION_FIELDS, ConfigError, FrictionParams, PlantParams, check_number
from ..run.scenario import Scenario
from .model import FRICTION_FITTED, Model, declared

__all__ = ['friction_cases', 'report_draws']


def load_report(path: str | Path) -> tuple[Model, dict[str, float], float]:
    """(final model, standard error of each fitted parameter, sample period [s]) of an
    identification directory (or its ``result.json``)."""
    path = Path(path)
    file = path / 'result.json' if path.is_dir() else path
    try:
        r = json.loads(file.read_text())
    except (OSError, ValueError) as exc:
        raise ConfigError(f'--from-ident: {file}: cannot read it as JSON ({exc}); give the --out directory '
                          f'of ./ipfric identify') from exc
    if not isinstance(r, dict) or 'ladder' not in r or 'identified' not in r:
        raise ConfigError(f'--from-ident: {file} is not the result of a ladder identification (no ladder and '
                          f'identified sections; a force-input record such as EMPS has no rig to simulate)')
    where = f'--from-ident: {file}'
    try:
        return _report_model(r, where)
    except (KeyError, TypeError, IndexError, AttributeError) as exc:
        raise ConfigError(f'{where}: malformed result: missing or invalid field {exc}; give the --out directory '
                          f'of ./ipfric identify') from None


def _report_model(r: dict, where: str) -> tuple[Model, dict[str, float], float]:
    """:func:`load_report` of the parsed ``result.json`` ``r``, every field it uses checked."""
    idf, ladder, data = r['identified'], r['ladder'], r.get('data')
    if not isinstance(ladder, list) or not ladder:
        raise ConfigError(f'{where}: the ladder is empty; allowed: the result of ./ipfric identify with its ladder')
    for section in ('plant', 'friction'):
        if not isinstance(idf, dict) or not isinstance(idf.get(section), dict):
            raise ConfigError(f'{where}: identified.{section} is missing; allowed: a mapping of its parameters')
    if not isinstance(data, dict):
        raise ConfigError(f'{where}: the data section is missing (sample_period_s, pendulum)')
    dt = data.get('sample_period_s')
    if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not (math.isfinite(dt) and 0 < dt <= 1.0):
        raise ConfigError(f'{where}: data.sample_period_s {dt!r} is invalid; allowed (0, 1] s')
    plant = PlantParams.from_dict(idf['plant'], f'{where}: identified.plant')
    fr = idf['friction']
    for k, v in fr.items():
        if k in FRICTION_FIELDS and v is not None:
            check_number(f'{where}: identified.friction.{k}', v, FRICTION_FIELDS[k])
    last = ladder[-1]
    model = declared(plant, FrictionParams(**fr), bool(data['pendulum']))
    for effect in last['effects']:
        model = model.with_effect(effect)
    model = model.with_free([p['name'] for p in last['params'] if p['fitted']])
    for p in last['params']:
        v, spec = p['value'], model.param(p['name'])
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not (math.isfinite(v) and spec.lo <= v <= spec.hi):
            raise ConfigError(f'{where}: ladder parameter {p["name"]} = {v!r} is invalid; allowed '
                              f'[{spec.lo:g}, {spec.hi:g}] {spec.unit}'.rstrip())
    model = model.with_values({p['name']: p['value'] for p in last['params']})
    std = {p['name']: float(p['std']) for p in last['params']
           if p['fitted'] and p['std'] is not None and math.isfinite(p['std']) and p['std'] > 0}
    return model, std, float(dt)


def report_draw(model: Model, std: dict[str, float], dt: float, base: Scenario, seed: int,
                index: int) -> tuple[dict, Scenario]:
    """Run ``index``: each parameter of ``std`` drawn from N(value, std^2) with the generator
    seeded by (seed, index), clipped to its bounds; (the drawn values, ``base`` with the
    drawn model's plant, friction and plant_truth; the controller stays ``base``'s)."""
    rng = np.random.default_rng([seed, index])
    names = sorted(std)
    return report_scenario(model, std, dt, base, dict(zip(names, rng.standard_normal(len(names)))))


def report_scenario(model: Model, std: dict[str, float], dt: float, base: Scenario,
                    z: dict[str, float]) -> tuple[dict, Scenario]:
    """Each parameter of ``z`` at value + z std, clipped to its bounds; (those values, ``base``
    with the model's plant, friction and plant_truth at them; the controller stays ``base``'s)."""
    values = {}
    for name, zi in z.items():
        p = model.param(name)
        values[name] = min(max(p.value + std[name] * zi, p.lo), p.hi)
    m = model.with_values(values)
    return values, replace(base, plant=m.plant_params(), friction=m.friction_params(), truth=m.plant_truth(dt))


def friction_shift(model: Model, std: dict[str, float], dt: float, base: Scenario, k: float) -> tuple[dict, Scenario]:
    """The friction law's fitted parameters (levels, viscous coefficient, Stribeck velocity) that
    have a standard error all at value + k std, the rest at their values (:func:`report_scenario`):
    k = +1 is the friction one standard error up on every coefficient at once."""
    names = sorted(n for n in std if n in FRICTION_FITTED)
    if not names:
        raise ConfigError('--from-ident: the report gives no standard error for the friction law\'s '
                          f'parameters ({", ".join(FRICTION_FITTED)})')
    return report_scenario(model, std, dt, base, dict.fromkeys(names, float(k)))


def friction_cases(path: str | Path, base: Scenario) -> tuple[list[tuple[str, float, Scenario]], str]:
    """The friction cases of a design check from an identification: (label, standard errors, scenario) with
    the friction at -1, 0 and +1 standard error (:func:`friction_shift`), and the axis they lie on."""
    model, std, dt = load_report(path)
    cases = [(f'friction {k:+d} SE' if k else 'identified', float(k), friction_shift(model, std, dt, base, k)[1])
             for k in (-1, 0, 1)]
    return cases, f'friction coefficients [standard errors of {path}]'


def report_draws(path: str | Path, base: Scenario, seed: int) -> tuple[Callable[[int], tuple[dict, Scenario]], dict]:
    """The Monte Carlo's draw of run i from an identification's parameter table (:func:`report_draw`),
    and what is drawn (for the summary)."""
    if not 0 <= seed <= 2**32 - 1:
        raise ConfigError(f'--seed: {seed} is out of range; allowed 0 .. {2**32 - 1} (run i draws with the seed '
                          f'(seed, i))')
    model, std, dt = load_report(path)
    return (partial(report_draw, model, std, dt, base, seed),
            {'from_ident': str(path), 'std': std,
             'meaning': 'value ~ N(identified value, std^2), independent, clipped to the bounds'})
