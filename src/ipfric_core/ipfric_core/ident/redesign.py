"""From an identified model back to the controller: export and the paper's loop.

:func:`export_scenario` writes the identified plant (friction as the paper's model,
undeclared effects as ``plant_truth``) with a controller designed on it, as a scenario
file the simulator and controller nodes read. :func:`close_the_loop` runs the paper's
story offline: a gain designed on the viscous model oscillates on a stick-slip plant;
the closed-loop data identify the friction; the gain designed on the identified model
runs on the same plant and the oscillation shrinks.
"""
from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import yaml

from .records import trajectory_record
from .effects import BASE_MODELS
from .identify import identify
from .report import write_report
from ..design.lqr import design
from ..physics.params import ConfigError, FrictionParams, PlantParams
from ..physics.rig import PlantTruth
from ..run.scenario import Scenario, load_scenario
from ..analysis.sweep import classify_run


def identified_friction(r: dict) -> FrictionParams:
    """The paper's friction model closest to the identified one (result dict of a search)."""
    f = r['friction']
    eff = set(r['effects_added']) | set(BASE_MODELS[r['base_model']])
    data = {'model': 'viscous', 'eps': max(0.0, f['eps'])}
    if 'coulomb' in eff:
        data.update(model='coulomb', mu_c=f['mu_c'], mu_s=f['mu_s'])
    if 'stribeck' in eff:
        data.update(model='exponential', v_s=f['v_s'], gamma=2.0)
    if 'presliding' in eff:
        data.update(model='dynamic', sigma0=f['sigma0'], sigma1=f['sigma1'])
        data.setdefault('v_s', 0.1)  # without a Stribeck excess (mu_s = mu_c) v_s plays no part
        data.setdefault('gamma', 2.0)
    try:
        return FrictionParams.from_dict(data, 'identified friction')
    except ConfigError as exc:
        raise ConfigError(f'{exc} (the identified friction does not fit a cart-pendulum scenario; '
                          f'are the data from the rig?)') from exc


def identified_truth(r: dict, dt: float) -> PlantTruth:
    """Undeclared effects found by the search, as the simulator's ``plant_truth``."""
    p = {k: v['value'] for k, v in r['params'].items()}
    eff = r['effects_added']
    vals = {}
    if 'cogging' in eff:
        vals.update(cogging_N=-math.copysign(math.hypot(p['cog_sin'], p['cog_cos']), p['cog_sin']),
                    cogging_period_m=p['cog_period'])
    if 'deadzone' in eff:
        vals['deadzone_V'] = p['dz']
    if 'saturation' in eff:
        vals['saturation_V'] = p['u_max']
    if 'delay' in eff:
        vals['input_delay_s'] = round(p['delay'] / dt) * dt
    if 'asymmetry' in eff:
        vals['asymmetry_N'] = p['dFc']
    if 'backlash' in eff:
        vals['backlash_m'] = p['gap']
    if 'sensor_bias' in eff:
        vals['bias_theta_rad'] = p['theta_bias']
    return PlantTruth(**vals)


def design_friction(friction: FrictionParams) -> FrictionParams:
    """The law the gain is designed on: the identified sticking law, linearized with the slope of
    tanh(delta v) (section 3.1, the design of gain (23)); a bristle model is designed on its
    static map (exponential), since the bristle state is not measured."""
    if friction.model == 'dynamic':
        return friction.replace(model='exponential', smoothing='none')
    return friction


def designed_gain(plant: PlantParams, friction: FrictionParams, Q, R: float) -> list:
    return [float(k) for k in design(plant, friction, Q, R).gain[:4]]


def export_scenario(path: str | Path, r: dict, base: Scenario, rig: Scenario | None = None) -> dict:
    """Write the identified scenario to ``path`` (and ``<stem>_on_rig.yaml`` when ``rig`` is given).

    sim_node: ``base``'s settings with the identified friction and effects; controller_node:
    the gain designed (LQR, ``base``'s Q and R) on the identified friction (:func:`design_friction`). With ``rig``, a
    second file runs that gain on the rig's own sim_node (the plant you ran on).
    """
    path = Path(path)
    friction = identified_friction(r)
    truth = identified_truth(r, base.sample_period)
    c = base.controller
    gain = designed_gain(base.plant, design_friction(friction), c.Q, c.R)
    ctrl = replace(c, gain_source='yaml', gain=tuple(gain), design_friction=None)
    path.parent.mkdir(parents=True, exist_ok=True)
    header = (f'# Identified plant ({r["base_model"]} + {", ".join(r["effects_added"]) or "no effect"}) and the\n'
              f'# LQR gain designed on it. Written by ./ipfric identify --export.\n')
    identified = replace(base, friction=friction, truth=truth, controller=ctrl)
    path.write_text(header + yaml.safe_dump(identified.to_ros_params(), sort_keys=False))
    load_scenario(path)  # the file must read back as a valid scenario
    out = {'scenario': str(path), 'friction': friction.to_dict(), 'plant_truth': truth.to_dict(), 'gain': gain}
    if rig is not None:
        on_rig = path.with_name(path.stem + '_on_rig.yaml')
        on_rig.write_text(f'# The rig of the identified run with the gain designed on the identified model.\n'
                          + yaml.safe_dump(replace(rig, controller=ctrl).to_ros_params(), sort_keys=False))
        load_scenario(on_rig)
        out['on_rig'] = str(on_rig)
    return out


def _oscillation(o, traj) -> dict:
    return {'class': o.cls, 'x_p2p_m': o.x_p2p, 'theta_p2p_rad': o.theta_p2p, 'period_s': o.period_crossings,
            'end_reason': traj.end_reason}


def close_the_loop(scenario_path: str | Path, out: str | Path, duration: float = 20.0,
                   base_model: str = 'viscous', plots: bool = True) -> dict:
    """Run, identify on the run's measured data, redesign, run again; amplitudes before/after."""
    out = Path(out)
    sc = load_scenario(scenario_path)
    o0, traj0 = classify_run(sc, duration)
    before = _oscillation(o0, traj0)
    rec = trajectory_record(f'{Path(scenario_path).name}, gain {[round(k, 2) for k in sc.gain()]}',
                            traj0, sc.plant)
    est, val = rec.split(0.6)
    r = write_report(identify(est, val, base_model), out / 'identification', plots)
    exported = export_scenario(out / 'identified.yaml', r, sc, rig=sc)
    sc1 = load_scenario(exported['on_rig'])
    after = _oscillation(*classify_run(sc1, duration))
    return {'scenario': str(scenario_path), 'duration_s': duration, 'gain_before': sc.gain(),
            'gain_after': exported['gain'], 'before': before, 'after': after,
            'identified': {k: r[k] for k in ('base_model', 'effects_added', 'friction', 'error_before',
                                              'error_after')},
            'export': exported, 'report': str(out / 'identification' / 'report.md')}
