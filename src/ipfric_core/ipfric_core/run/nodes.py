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
from .scenario import load_scenario

__all__ = ['NODES', 'OVERRIDES', 'parse_overrides', 'write_run_scenario', 'node_parameters', 'ros_args']

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


def write_run_scenario(config, out, overrides: dict | None = None) -> Path:
    """Validate ``config`` with ``overrides`` applied; write it to ``out``/scenario.yaml.

    Raises ConfigError (named field) for a bad scenario or a bag already in ``out``.
    """
    config, out = Path(config), Path(out)
    load_scenario(config)
    data = load_yaml(config)
    overrides = dict(overrides or {})
    duration = overrides.get('duration')
    if duration is not None and not (math.isfinite(duration) and duration >= 0):
        raise ConfigError(f'duration: {duration!r} must be >= 0 s (simulated seconds)')
    for name, value in overrides.items():
        node, param = OVERRIDES[name][:2]
        data[node]['ros__parameters'][param] = value
    out.mkdir(parents=True, exist_ok=True)
    if (out / BAG_NAME).exists():
        raise ConfigError(f'{out / BAG_NAME} exists already; choose another output directory')
    path = out / CONFIG_NAME
    header = f'# ipfric run of {config}' + ''.join(f', {k} {v}' for k, v in overrides.items()) + '\n'
    path.write_text(header + yaml.safe_dump(data, sort_keys=False))
    load_scenario(path)
    return path


def node_parameters(scenario, out) -> dict:
    """Every node's (parameter file or None, parameters on top of it), by node name.

    ``scenario``: the run scenario (:func:`write_run_scenario`); ``out``: the run directory
    (bag in ``out``/bag, the simulator's result in ``out``/sim_result.json).
    """
    scenario, out = str(scenario), Path(out)
    return {
        'recorder': (None, {'output': str(out / BAG_NAME), 'scenario_file': scenario}),
        'controller_node': (scenario, {'min_command_subscribers': 2, 'use_sim_time': True}),
        'sim_node': (scenario, {'wait_for_recorder': True, 'result_file': str(out / RESULT_NAME)}),
    }


def ros_args(params_file, params: dict) -> list:
    """``--ros-args`` arguments (without that flag) for a parameter file and parameters."""
    args = ['--params-file', str(params_file)] if params_file else []
    for k, v in params.items():
        args += ['-p', f'{k}:={str(v).lower() if isinstance(v, bool) else v}']
    return args
