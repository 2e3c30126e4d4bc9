"""A run scenario (a ROS 2 parameter file) and the supervisor of the node processes.

Modules: nodes, runner, scenario. Every public name below is loaded from its module on
first use, so importing the package stays cheap."""
from __future__ import annotations

import importlib

#: public name -> module that defines it
_WHERE = {
    'CONFIG_NAME': 'nodes',
    'CONTROLLER_FIELDS': 'scenario',
    'ControllerSettings': 'scenario',
    'DEFAULT_Q': 'scenario',
    'GAIN': 'scenario',
    'GAIN_SOURCES': 'scenario',
    'NODES': 'nodes',
    'OVERRIDES': 'nodes',
    'ROOT': 'runner',
    'Run': 'runner',
    'RunResult': 'runner',
    'SIM_FIELDS': 'scenario',
    'Scenario': 'scenario',
    'SimSettings': 'scenario',
    'TIME_MODES': 'scenario',
    'TRUTH_FIELDS': 'scenario',
    'WEIGHT': 'scenario',
    'cmd_run': 'runner',
    'describe_exit': 'runner',
    'domain_in_use': 'runner',
    'executable': 'runner',
    'last_problem': 'runner',
    'load_scenario': 'scenario',
    'nest': 'scenario',
    'node_parameters': 'nodes',
    'parse_overrides': 'nodes',
    'parse_controller': 'scenario',
    'parse_sim': 'scenario',
    'pick_domain': 'runner',
    'ros_args': 'nodes',
    'ros_environment': 'runner',
    'run': 'runner',
    'scenario_from_ros_params': 'scenario',
    'write_run_scenario': 'nodes',
}

__all__ = sorted(_WHERE) + ['nodes', 'runner', 'scenario']


def __getattr__(name: str):
    if name in _WHERE:
        return getattr(importlib.import_module(f'.{_WHERE[name]}', __name__), name)
    if name in __all__:
        return importlib.import_module(f'.{name}', __name__)
    raise AttributeError(f'module {__name__!r} has no attribute {name!r}')
