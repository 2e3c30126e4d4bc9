"""What ``./ipfric identify`` does with its inputs: the paper's tables, a measured record, or
the closed-loop redesign, each into a report directory.

:func:`identify_record` reads the declared model once (:func:`~ipfric_core.ident.model.read_declared`),
loads the record with that plant, splits it into estimation and validation parts (or takes
a second file for validation), and runs the ladder (:mod:`ipfric_core.ident.ladder`) or, for a
force-input record without a declared plant (EMPS), the equation-error search
(:mod:`ipfric_core.ident.equation_error`); the report is written into the output directory,
and the identified rig exported as a scenario when asked.
"""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from ..analysis.records import load
from ..design.estimation import load_table5, load_table6
from ..physics.params import ConfigError, PlantParams
from ..run.scenario import DEFAULT_SCENARIO, load_scenario
from .effects import EFFECTS
from .equation_error import identify, identify_steady
from .ladder import run_ladder
from .ladder_report import write_ladder_report
from .model import declared, read_declared
from .redesign import export_scenario
from .report import write_report

__all__ = ['SPLIT_RANGE', 'candidate_effects', 'identify_tables', 'identify_record']

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


def identify_record(data: str | Path, out: str | Path, plant_file: str | Path | None = None,
                    base: str = 'exponential', free: str | None = None, effects: str | None = None,
                    columns: dict | None = None, cart_alone: bool = False, validation: str | Path | None = None,
                    split: float = 0.6, plots: bool = True, export: str | Path | None = None,
                    scenario: str | Path | None = None, rig: str | Path | None = None,
                    progress: Callable[[str], None] | None = None) -> dict:
    """Identify the record ``data`` (a bag or run directory, a CSV, an EMPS .mat) against the declared
    model of ``plant_file`` and write the report into ``out``; the result (``result.json``'s content).

    ``free``: known constants to fit too ('M,alpha'); ``effects``: the candidate effects ('a,b', default
    all); ``validation``: a second file to judge on, else the last 1 - ``split`` of ``data``; ``export``:
    write the identified rig as a scenario (settings, Q and R of ``scenario``; with ``rig``, also that
    rig with the new gain)."""
    allowed = candidate_effects(effects)
    plant, friction = read_declared(plant_file, base)
    rec = load(data, plant, columns, cart_alone)
    if validation:
        est, val = rec, load(validation, plant, columns, cart_alone)
    else:
        if not SPLIT_RANGE[0] <= split <= SPLIT_RANGE[1]:
            raise ConfigError(f'--split: {split:g} is out of range; allowed [{SPLIT_RANGE[0]:g}, {SPLIT_RANGE[1]:g}]')
        est, val = rec.split(split)
    if Path(data).suffix.lower() == '.mat':
        return write_report(identify(est, val, base, allowed), out, plots)
    model = declared(plant or rec.plant or PlantParams(), friction, rec.theta is not None)
    if free:
        model = model.freeing([n.strip() for n in free.split(',')])
    r = write_ladder_report(run_ladder(est, val, model, allowed, progress), out, plots)
    if export:
        r['export'] = export_scenario(export, r['ladder'][-1]['step'], r['identified'],
                                      load_scenario(scenario or DEFAULT_SCENARIO),
                                      load_scenario(rig) if rig else None)
    return r
