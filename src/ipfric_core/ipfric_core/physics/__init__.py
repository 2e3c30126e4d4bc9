"""Physics of the rig (paper sections 2 and 6): parameters, friction laws, the plant, stick-
slip integration, encoders and undeclared effects, the sampled controller and closed loop.
Knows nothing of ROS, design or data.

The names below are what a user of the library calls; each is loaded from its module on
first use, so importing the package stays cheap.
"""
from ..lazy import lazy_package

__all__, __getattr__ = lazy_package(__name__, __path__, {
    'params': ('PlantParams', 'FrictionParams', 'ConfigError', 'load_yaml'),
    'friction': ('Friction',),
    'plant': ('CartPendulum',),
    'simulate': ('Simulator',),
    'encoder': ('quantize',),
    'rig': ('PlantTruth', 'Rig'),
    'controller': ('StateFeedback',),
    'closedloop': ('Trajectory', 'run_closed_loop'),
})
