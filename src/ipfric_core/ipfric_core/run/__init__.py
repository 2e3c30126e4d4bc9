"""A run scenario (a ROS 2 parameter file) and the supervisor of the node processes.

Modules: nodes, runner, scenario. Every public name below is loaded from its module on first
use, so importing the package stays cheap."""
from __future__ import annotations

from ..lazy import lazy_getattr

#: public name -> module that defines it
_WHERE = {
    'BAG_NAME': 'nodes',
    'CONFIG_NAME': 'nodes',
    'CONTROLLER_FIELDS': 'scenario',
    'ControllerSettings': 'scenario',
    'DEFAULT_Q': 'scenario',
    'DOMAINS': 'runner',
    'EXIT_FAULT': 'runner',
    'EXIT_FELL': 'runner',
    'GAIN': 'scenario',
    'GAIN_SOURCES': 'scenario',
    'NODES': 'nodes',
    'OVERRIDES': 'nodes',
    'PLANT_TRUTH_FIELDS': 'scenario',
    'PR_SET_PDEATHSIG': 'runner',
    'RECORDER_PARAMS': 'scenario',
    'RESULT_NAME': 'nodes',
    'ROOT': 'runner',
    'Run': 'runner',
    'RunResult': 'runner',
    'SIM_FIELDS': 'scenario',
    'SUPERVISED': 'runner',
    'Scenario': 'scenario',
    'SimSettings': 'scenario',
    'TIME_MODES': 'scenario',
    'cmd_run': 'runner',
    'describe_exit': 'runner',
    'die_with_parent': 'runner',
    'domain_in_use': 'runner',
    'executable': 'runner',
    'last_problem': 'runner',
    'load_scenario': 'scenario',
    'nest': 'scenario',
    'node_parameters': 'nodes',
    'parse_controller': 'scenario',
    'parse_overrides': 'nodes',
    'parse_sim': 'scenario',
    'pick_domain': 'runner',
    'ros_args': 'nodes',
    'ros_environment': 'runner',
    'run': 'runner',
    'scenario_from_ros_params': 'scenario',
    'sim_faults': 'runner',
    'write_run_scenario': 'nodes',
}
_MODULES = ['nodes', 'runner', 'scenario']

__all__ = sorted(_WHERE) + _MODULES
__getattr__ = lazy_getattr(__name__, _WHERE, _MODULES)
