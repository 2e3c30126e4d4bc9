"""From an identified model back to the controller: export and the paper's loop.

:func:`export_scenario` writes the identified plant (friction as the paper's model,
undeclared effects as ``plant_truth``) with a controller designed on it, as a scenario
file the simulator and controller nodes read. :func:`close_the_loop` runs the paper's
story offline: a gain designed on the viscous model oscillates on a stick-slip plant;
the closed-loop data identify the friction; the gain designed on the identified model
runs on the same plant and the oscillation shrinks.
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import yaml

from ..analysis.records import trajectory_record
from ..design.lqr import design
from ..physics.params import FrictionParams, PlantParams
from ..physics.rig import PlantTruth
from ..run.scenario import Scenario, load_scenario
from ..study.outcome import classify_run
from .ladder import run_ladder
from .ladder_report import write_ladder_report
from .model import load_declared

__all__ = ['export_scenario', 'close_the_loop']


def design_friction(friction: FrictionParams) -> FrictionParams:
    """The law the gain is designed on: the identified sticking law, linearized with the slope of
    tanh(delta v) (section 3.1, the design of gain (23)); a bristle model is designed on its
    static map (exponential), since the bristle state is not measured."""
    if friction.model == 'dynamic':
        return friction.replace(model='exponential', smoothing='none')
    return friction


def designed_gain(plant: PlantParams, friction: FrictionParams, Q, R: float) -> list:
    return [float(k) for k in design(plant, friction, Q, R).gain[:4]]


def export_scenario(path: str | Path, label: str, idf: dict, base: Scenario, rig: Scenario | None = None) -> dict:
    """Write the identified rig to ``path`` (and ``<stem>_on_rig.yaml`` when ``rig`` is given).

    ``idf``: the identified model's sections (:func:`ladder_report.identified`): its own plant
    constants, its friction as coefficients of its own normal force, every effect parameter
    as ``plant_truth`` (cogging phase, asymmetry, offset included). sim_node: ``base``'s
    settings with them; controller_node: the gain designed (LQR, ``base``'s Q and R) on the
    identified plant and friction (:func:`design_friction`). With ``rig``, a second file runs
    that gain on the rig's own sim_node (the plant you ran on).
    """
    path = Path(path)
    plant = PlantParams(**idf['plant'])
    friction = FrictionParams(**idf['friction'])
    truth = PlantTruth(**idf['plant_truth'])
    c = base.controller
    gain = designed_gain(plant, design_friction(friction), c.Q, c.R)
    ctrl = replace(c, gain_source='yaml', gain=tuple(gain), design_friction=None)
    path.parent.mkdir(parents=True, exist_ok=True)
    header = (f'# Identified rig ({label}) and the LQR gain designed on it. Written by ./ipfric identify --export.\n')
    identified = replace(base, plant=plant, friction=friction, truth=truth, controller=ctrl)
    path.write_text(header + yaml.safe_dump(identified.to_ros_params(), sort_keys=False))
    load_scenario(path)  # the file must read back as a valid scenario
    out = {'scenario': str(path), 'friction': friction.to_dict(), 'plant_truth': truth.to_dict(), 'gain': gain}
    if rig is not None:
        on_rig = path.with_name(path.stem + '_on_rig.yaml')
        on_rig.write_text('# The rig of the identified run with the gain designed on the identified model.\n'
                          + yaml.safe_dump(replace(rig, controller=ctrl).to_ros_params(), sort_keys=False))
        load_scenario(on_rig)
        out['on_rig'] = str(on_rig)
    return out


def _oscillation(o, traj) -> dict:
    return {'class': o.cls, 'x_p2p_m': o.x_p2p, 'theta_p2p_rad': o.theta_p2p, 'period_s': o.period_crossings,
            'end_reason': traj.end_reason}


def close_the_loop(scenario_path: str | Path, out: str | Path, duration: float = 20.0,
                   base_model: str = 'exponential', plots: bool = True) -> dict:
    """Run, identify on the run's measured data, redesign, run again; amplitudes before/after.

    The declared model is the scenario's design side: its plant and the paper's ``base_model``
    friction law (the friction the controller's designer assumed is refitted by the ladder)."""
    out = Path(out)
    sc = load_scenario(scenario_path)
    o0, traj0 = classify_run(sc, duration)
    before = _oscillation(o0, traj0)
    rec = trajectory_record(f'{Path(scenario_path).name}, gain {[round(k, 2) for k in sc.gain()]}',
                            traj0, sc.plant)
    est, val = rec.split(0.6)
    model = load_declared(None, base_model, True, sc.plant)
    r = write_ladder_report(run_ladder(est, val, model), out / 'identification', plots)
    idf = r['identified']
    exported = export_scenario(out / 'identified.yaml', r['ladder'][-1]['step'], idf, sc, rig=sc)
    sc1 = load_scenario(exported['on_rig'])
    after = _oscillation(*classify_run(sc1, duration))
    return {'scenario': str(scenario_path), 'duration_s': duration, 'gain_before': sc.gain(),
            'gain_after': exported['gain'], 'before': before, 'after': after,
            'identified': {'base_model': base_model, 'effects_added': r['effects_added'],
                           'friction': idf['friction'], 'plant_truth': idf['plant_truth'],
                           'ladder': [{'step': s['step'], 'validation': s['validation']} for s in r['ladder']]},
            'export': exported, 'report': str(out / 'identification' / 'report.md')}
