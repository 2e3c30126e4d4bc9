"""The nodes of a run and their parameters: one definition for ``./ipfric run`` and ``ros2 launch``.

A run is three processes (:data:`NODES`) started on one parameter file, the *run scenario*:
the user's scenario file with the run's launch arguments applied (:data:`OVERRIDES`,
e.g. ``duration``), validated and written to ``OUT/scenario.yaml``
(:func:`write_run_scenario`). :func:`node_parameters` gives every node its parameter file
and the parameters set on top of it. ``./ipfric run`` renders them as ``--ros-args``
command lines (:func:`ros_args`); the launch file of ``ipfric_bringup`` as launch_ros
``Node`` actions. Pure Python, no ROS import.
"""
from __future__ import annotations

import math
from pathlib import Path

import yaml

from ..physics.params import ConfigError, load_yaml
from .scenario import SECTION_KEYS, load_scenario, node_sections, scenario_from_sections, scenario_path

__all__ = ['NODES', 'OVERRIDES', 'REALTIME', 'parse_overrides', 'write_run_scenario', 'node_parameters', 'ros_args']

#: The processes of a run in start order: name -> (package, executable).
NODES = {
    'recorder': ('ipfric_record', 'recorder'),
    'controller_node': ('ipfric_controller', 'controller_node'),
    'sim_node': ('ipfric_sim', 'sim_node'),
}

#: Run arguments that replace a parameter of the scenario file:
#: name -> (node, parameter, type, description).
OVERRIDES = {
    'duration': ('sim_node', 'duration', float, 'simulated seconds, 0 = until stopped'),
    'time_mode': ('sim_node', 'time_mode', str, 'lockstep | realtime'),
    'theta0': ('sim_node', 'theta0', float, 'initial angle [rad]'),
    'delay': ('controller_node', 'delay', float, 'artificial controller delay tau [s]'),
}

CONFIG_NAME = 'scenario.yaml'
BAG_NAME = 'bag'
RESULT_NAME = 'sim_result.json'


def parse_overrides(values: dict) -> dict:
    """Launch-argument strings (name -> str, '' = not given) as typed overrides.

    Unknown names and values that are not numbers where numbers are needed are refused
    with a :class:`ConfigError` naming the argument.
    """
    out = {}
    for name, text in values.items():
        if name not in OVERRIDES:
            raise ConfigError(f'run argument {name!r} unknown; allowed: {", ".join(OVERRIDES)}')
        if text is None or str(text).strip() == '':
            continue
        kind = OVERRIDES[name][2]
        try:
            out[name] = kind(text)
        except ValueError as exc:
            raise ConfigError(f'run argument {name}: {text!r} is not a number') from exc
    return out


def write_run_scenario(config, out, overrides: dict | None = None, namespace: str = '/') -> Path:
    """Validate ``config`` (a path or an installed scenario's name) as the nodes in ``namespace``
    read it, with ``overrides`` applied; then write it to ``out``/scenario.yaml, one section per
    node in the wildcard form (``/**/sim_node``).

    Raises ConfigError (named field) for a bad scenario or a bag already in ``out``; nothing is
    created then.
    """
    config, out = scenario_path(config), Path(out)
    sections = node_sections(load_yaml(config), namespace, config)
    scenario_from_sections(sections, config, namespace)
    overrides = dict(overrides or {})
    duration = overrides.get('duration')
    if duration is not None and not (math.isfinite(duration) and duration >= 0):
        raise ConfigError(f'duration: {duration!r} must be >= 0 s (simulated seconds)')
    for name, value in overrides.items():
        node, param = OVERRIDES[name][:2]
        sections[node][param] = value
    scenario_from_sections(sections, f'{config} with {overrides}', namespace)
    if (out / BAG_NAME).exists():
        raise ConfigError(f'{out / BAG_NAME} exists already; choose another output directory')
    out.mkdir(parents=True, exist_ok=True)
    path = out / CONFIG_NAME
    header = f'# ipfric run of {config}' + ''.join(f', {k} {v}' for k, v in overrides.items()) + '\n'
    data = {SECTION_KEYS[node]: {'ros__parameters': params} for node, params in sections.items()}
    path.write_text(header + yaml.safe_dump(data, sort_keys=False))
    return path


#: What the sample loop of a realtime run gets (ipfric_ros.realtime), by node: real-time
#: scheduling of every thread (refused without the privilege, which the nodes log); the recorder
#: stays at its default niceness below them. Binding each to a CPU of its own was measured and
#: left out: on 2 cores a process's middleware threads then wait for its loop (docs/ros-stack.md).
REALTIME = {'sim_node': {'realtime_priority': 80}, 'controller_node': {'realtime_priority': 79}}


def node_parameters(scenario, out) -> dict:
    """Every node's (parameter file or None, parameters on top of it), by node name.

    ``scenario``: the run scenario (:func:`write_run_scenario`); ``out``: the run directory
    (bag in ``out``/bag, the simulator's result in ``out``/sim_result.json). A realtime run adds
    :data:`REALTIME`.
    """
    realtime = load_scenario(scenario).sim.time_mode == 'realtime'
    scenario, out = str(scenario), Path(out)
    params = {
        'recorder': (None, {'output': str(out / BAG_NAME), 'scenario_file': scenario}),
        'controller_node': (scenario, {'use_sim_time': True}),
        'sim_node': (scenario, {'result_file': str(out / RESULT_NAME)}),
    }
    for name, extra in REALTIME.items() if realtime else ():
        params[name][1].update(extra)
    return params


def ros_args(params_file, params: dict, namespace: str = '/') -> list:
    """``--ros-args`` arguments (without that flag) for a parameter file and parameters, in ``namespace``."""
    args = ['-r', f'__ns:={namespace}'] if namespace not in ('/', '', None) else []
    args += ['--params-file', str(params_file)] if params_file else []
    for k, v in params.items():
        args += ['-p', f'{k}:={str(v).lower() if isinstance(v, bool) else v}']
    return args
