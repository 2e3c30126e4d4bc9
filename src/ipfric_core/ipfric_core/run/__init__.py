"""One experiment: a scenario (the parameter file of the simulator and controller nodes) and its
closed-loop run through the ROS 2 nodes, supervised and recorded.

Modules: demo, nodes, runner, scenario.
The names below are what a user of the library calls; each is loaded from its module on
first use, so importing the package stays cheap.
"""
from __future__ import annotations

from ..lazy import lazy_getattr

#: public name -> module that defines it
_WHERE = {
    'Scenario': 'scenario',
    'load_scenario': 'scenario',
    'Run': 'runner',
    'RunResult': 'runner',
    'run': 'runner',
}
_MODULES = ['demo', 'nodes', 'runner', 'scenario']
__all__ = sorted(_WHERE)
__getattr__ = lazy_getattr(__name__, _WHERE, _MODULES)
