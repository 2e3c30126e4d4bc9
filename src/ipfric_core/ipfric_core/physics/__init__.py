"""Physics of the rig (paper sections 2 and 6): parameters, friction laws, the plant, stick-
slip integration, encoders and undeclared effects, the sampled controller and closed loop.
Knows nothing of ROS, design or data.

Modules: closedloop, compiled, controller, encoder, friction, params, plant, rig, simulate.
Every public name below is loaded from its module on first use, so importing the package
stays cheap."""
from __future__ import annotations

from ..lazy import lazy_getattr

#: public name -> module that defines it
_WHERE = {
    'CACHE_DIR': 'compiled',
    'CartPendulum': 'plant',
    'ConfigError': 'params',
    'END_REASONS': 'closedloop',
    'ENGINES': 'closedloop',
    'FRICTION_FIELDS': 'params',
    'FRICTION_MODELS': 'params',
    'FRICTION_REQUIRED': 'params',
    'FeedbackSpec': 'controller',
    'Field': 'params',
    'Friction': 'friction',
    'FrictionParams': 'params',
    'MAX_EVENTS': 'simulate',
    'MODEL_CODES': 'friction',
    'NO_EXTRA_FORCE': 'plant',
    'PLANT_FIELDS': 'params',
    'PlantParams': 'params',
    'PlantTruth': 'rig',
    'Rig': 'rig',
    'RigSpec': 'rig',
    'SMOOTHING': 'params',
    'STALE_AFTER_S': 'compiled',
    'Simulator': 'simulate',
    'StateFeedback': 'controller',
    'Trajectory': 'closedloop',
    'XTOL': 'simulate',
    'accelerations': 'plant',
    'advance': 'simulate',
    'apply_input_effects': 'rig',
    'bristle_path': 'friction',
    'bristle_rate': 'friction',
    'cache_root': 'compiled',
    'check_choice': 'params',
    'check_keys': 'params',
    'check_number': 'params',
    'compiled_unsupported': 'closedloop',
    'delay_samples': 'controller',
    'feedback': 'controller',
    'filter_coefficient': 'controller',
    'filtered_rate': 'controller',
    'friction_force': 'friction',
    'friction_forces': 'friction',
    'friction_now': 'simulate',
    'friction_vector': 'friction',
    'held': 'simulate',
    'held_force': 'plant',
    'held_forces': 'plant',
    'holding_margin': 'friction',
    'holds': 'friction',
    'input_effects': 'rig',
    'inputs_through': 'rig',
    'load_yaml': 'params',
    'motor_force': 'plant',
    'pendulum_residuals': 'plant',
    'plant_vector': 'plant',
    'play': 'rig',
    'prune': 'compiled',
    'quantize': 'encoder',
    'rates': 'plant',
    'required_forces': 'plant',
    'rk4_slide': 'simulate',
    'rk4_stuck': 'simulate',
    'run_closed_loop': 'closedloop',
    'sensor_reading': 'rig',
    'sliding_level': 'friction',
    'source_key': 'compiled',
    'static_friction': 'friction',
    'static_limit': 'friction',
    'sticks': 'friction',
    'stribeck_level': 'friction',
    'stuck_theta_acceleration': 'plant',
    'undeclared_force': 'plant',
    'undeclared_forces': 'plant',
    'use_cache': 'compiled',
    'warm_up': 'closedloop',
}
_MODULES = ['closedloop', 'compiled', 'controller', 'encoder', 'friction', 'params', 'plant', 'rig',
            'simulate']

__all__ = sorted(_WHERE) + _MODULES
__getattr__ = lazy_getattr(__name__, _WHERE, _MODULES)
