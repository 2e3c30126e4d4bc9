"""One experiment: a scenario (the parameter file of the simulator and controller nodes) and its
closed-loop run through the ROS 2 nodes, supervised and recorded.

The names below are what a user of the library calls; each is loaded from its module on
first use, so importing the package stays cheap.
"""
from ..lazy import lazy_package

__all__, __getattr__ = lazy_package(__name__, __path__, {
    'scenario': ('Scenario', 'load_scenario'),
    'runner': ('Run', 'RunResult', 'run'),
})
