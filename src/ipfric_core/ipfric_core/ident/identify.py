"""What ``./ipfric identify`` does with its inputs: the paper's tables, a measured record, or
the closed-loop redesign, each into a report directory.

:func:`identify_record` reads the declared model once (:func:`~ipfric_core.ident.model.read_declared`),
loads the record with that plant, splits it into estimation and validation parts (or takes
a second file for validation), and runs the ladder (:mod:`ipfric_core.ident.ladder`). A
force-input record that declares no plant (EMPS: the force is gain * u) starts the ladder from
its force balance (:func:`force_input_model`), and its report adds the relative force error of
each step (the EMPS benchmark's metric). With a test record, the final model is also run free
over it (:mod:`ipfric_core.ident.held_out`). The report is written into the output directory,
and the identified rig exported as a scenario when asked.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

from ..analysis.records import Record, load
from ..design.estimation import load_table5, load_table6
from ..physics.params import ConfigError, FrictionParams, PlantParams
from ..run.scenario import DEFAULT_SCENARIO, load_scenario
from .effects import EFFECTS, PARAMS, static_level
from .equation_error import base_fit, force_error, identify_steady, structure_fit
from .held_out import INIT_SAMPLES, free_run
from .judging import verdict
from .ladder import Step, run_ladder
from .ladder_report import write_ladder_report
from .model import LAW_PARAMS, Model, declared, read_declared
from .problem import Problem
from .redesign import export_scenario

__all__ = ['SPLIT_RANGE', 'candidate_effects', 'identify_tables', 'force_input_model', 'identify_record']

#: the estimation share of a record split in time
SPLIT_RANGE = (0.2, 0.9)


def candidate_effects(text: str | None) -> list[str] | None:
    """The effects of ``--effects a,b`` (None: the whole library), each checked against the library."""
    if not text:
        return None
    allowed = [e.strip() for e in text.split(',')]
    bad = [e for e in allowed if e not in EFFECTS]
    if bad:
        raise ConfigError(f'--effects: unknown effect(s) {", ".join(bad)}; allowed: {", ".join(EFFECTS)}')
    return allowed


def identify_tables(tables: str | Path, plant_file: str | Path | None = None) -> dict:
    """Tables 5 and 6 of the paper (``tables``: their directory) through the force balance, with the
    plant of ``plant_file`` (default Table 1)."""
    plant, _ = read_declared(plant_file, 'exponential')
    d = Path(tables)
    volts, vels, _, _, aside = load_table5(d / 'table5_constant_voltage.csv')
    rep = identify_steady(plant or PlantParams(), volts, vels, load_table6(d / 'table6_breakaway_voltage.csv'))
    rep['runs_set_aside'] = [{'voltage_V': a, 'value_mps': b, 'row_average_mps': c} for a, b, c in aside]
    return rep


def force_input_model(rec: Record, law: str) -> Model:
    """The declared model of a force-input record that declares no plant (EMPS): the mass and the
    friction of its force balance (:func:`~ipfric_core.ident.equation_error.base_fit`) by the richest
    law up to ``law`` whose Coulomb level stays off its bound (the Stribeck curve of a track without
    stiction puts it on 0: the Coulomb law answers), the record's gain as alpha and its back-EMF as
    beta, the cart alone. The ladder takes it as its hypothesis."""
    laws = list(LAW_PARAMS)[:list(LAW_PARAMS).index(law) + 1]
    for name in reversed(laws):
        f = base_fit(rec, name).params
        if name == 'viscous' or f['Fc'] > 1e-3 * PARAMS['Fc'].typical:
            law = name
            break
    plant = PlantParams(M=f['M'], alpha=rec.gain, beta=rec.back_emf)
    fn = plant.M * plant.g
    fc = f.get('Fc', 0.0)
    friction = FrictionParams(model=law, eps=f['eps'], mu_c=fc / fn,
                              mu_s=static_level(fc, f.get('Fs_excess', 0.0)) / fn,
                              **{k: f[k] for k in ('v_s', 'sigma0', 'sigma1') if k in f})
    return declared(plant, friction, False)


def balanced(res: dict) -> None:
    """A force-input record's last step: the ladder's final structure with every value from the force
    balance of the estimation record (:func:`~ipfric_core.ident.equation_error.structure_fit`), added
    to ``res`` when it runs at least as close to the validation record. With the force measured in a
    closed position loop, short simulations drift with the loop's errors, and the balance is the
    steadier estimate (the EMPS benchmark's reference models are fitted so)."""
    last = res['steps'][-1]
    f = structure_fit(res['estimation'], {p.name: p.value for p in last.model.params}, last.model.law,
                      last.model.effects)
    model = last.model.with_values(f.params).with_free(f.params)
    pe, pv = Problem(res['estimation']), Problem(res['validation'])
    summ = pv.summary(model)
    if summ['x_rms_counts'] > last.val['x_rms_counts']:
        return
    res['steps'].append(Step('force balance', model, f.std, pe.summary(model), summ,
                             [f'values from the force balance of {res["estimation"].name}']))
    res['verdict'] = {**res['verdict'], **verdict(pv, model)}


def force_errors(res: dict) -> list[dict]:
    """The relative force error of each step of a ladder on its estimation and validation records."""
    out = []
    for s in res['steps']:
        p = {q.name: q.value for q in s.model.params}
        out.append({'step': s.label, **{part: force_error(res[part], p, s.model.law, s.model.effects)
                                        for part in ('estimation', 'validation')}})
    return out


def identify_record(data: str | Path, out: str | Path, plant_file: str | Path | None = None,
                    base: str = 'exponential', free: str | None = None, effects: str | None = None,
                    columns: dict | None = None, cart_alone: bool = False, validation: str | Path | None = None,
                    split: float = 0.6, plots: bool = True, export: str | Path | None = None,
                    scenario: str | Path | None = None, rig: str | Path | None = None,
                    progress: Callable[[str], None] | None = None, test: str | Path | None = None,
                    test_init: int = INIT_SAMPLES, time_limit: float | None = None) -> dict:
    """Identify the record ``data`` (a bag or run directory, a CSV, an EMPS .mat) against the declared
    model of ``plant_file`` and write the report into ``out``; the result (``result.json``'s content).

    ``free``: known constants to fit too ('M,alpha'); ``effects``: the candidate effects ('a,b', default
    all); ``validation``: a second file to judge on, else the last 1 - ``split`` of ``data``'s motion;
    ``test``: a held-out file the final model runs free over from its first ``test_init`` readings;
    ``export``: write the identified rig as a scenario (settings, Q and R of ``scenario``; with ``rig``,
    also that rig with the new gain); ``time_limit`` [s]: no round of the ladder after the first starts
    once it has run this long (:func:`~ipfric_core.ident.ladder.run_ladder`)."""
    if time_limit is not None and not (math.isfinite(time_limit) and time_limit > 0):
        raise ConfigError(f'--time-limit: {time_limit:g} s; allowed a positive finite number of seconds')
    allowed = candidate_effects(effects)
    plant, friction = read_declared(plant_file, base)
    rec = load(data, plant, columns, cart_alone)
    if not SPLIT_RANGE[0] <= split <= SPLIT_RANGE[1]:
        raise ConfigError(f'--split: {split:g} is out of range; allowed [{SPLIT_RANGE[0]:g}, {SPLIT_RANGE[1]:g}]')
    held_out = load(test, plant, columns, cart_alone) if test else None
    est, val = (rec, load(validation, plant, columns, cart_alone)) if validation else rec.split(split)
    force_input = plant is None and rec.plant is None
    if force_input:
        model = force_input_model(est, base)
    else:
        model = declared(plant or rec.plant or PlantParams(), friction, rec.theta is not None)
    if free:
        model = model.freeing([n.strip() for n in free.split(',')])
    res = run_ladder(est, val, model, allowed, progress, time_limit)
    if force_input:
        balanced(res)
        res['force_error'] = force_errors(res)
    if held_out is not None:
        res['test'] = free_run(res['steps'][-1].model, held_out, test_init)
    r = write_ladder_report(res, out, plots)
    if export:
        r['export'] = export_scenario(export, r['ladder'][-1]['step'], r['identified'],
                                      load_scenario(scenario or DEFAULT_SCENARIO),
                                      load_scenario(rig) if rig else None)
    return r
