"""Physics of the rig (paper sections 2 and 6): parameters, friction laws, the plant, stick-
slip integration, encoders and undeclared effects, the sampled controller and closed loop.
Knows nothing of ROS, design or data.

Modules: closedloop, compiled, controller, encoder, friction, params, plant, rig, simulate.
The names below are what a user of the library calls; each is loaded from its module on
first use, so importing the package stays cheap.
"""
from __future__ import annotations

from ..lazy import lazy_getattr

#: public name -> module that defines it
_WHERE = {
    'PlantParams': 'params',
    'FrictionParams': 'params',
    'ConfigError': 'params',
    'load_yaml': 'params',
    'Friction': 'friction',
    'CartPendulum': 'plant',
    'Simulator': 'simulate',
    'quantize': 'encoder',
    'PlantTruth': 'rig',
    'Rig': 'rig',
    'StateFeedback': 'controller',
    'Trajectory': 'closedloop',
    'run_closed_loop': 'closedloop',
}
_MODULES = ['closedloop', 'compiled', 'controller', 'encoder', 'friction', 'params', 'plant', 'rig', 'simulate']
__all__ = sorted(_WHERE)
__getattr__ = lazy_getattr(__name__, _WHERE, _MODULES)
