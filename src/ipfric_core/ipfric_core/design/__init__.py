"""Design on the physics (paper sections 3-5): linearization, LQR, Routh-Hurwitz, the critical
delay, the describing-function prediction of the hunting, friction estimates from the appendix
tables, the printed numbers.

Modules: continuation, critical_delay, describing, estimation, linearize, lqr, orbit, paper, paperconfig,
reports, stability.
Every public name below is loaded from its module on first use, so importing the package
stays cheap."""
from __future__ import annotations

from ..lazy import lazy_getattr

#: public name -> module that defines it
_WHERE = {
    'AMPLITUDE_RANGE': 'describing',
    'BREAKAWAY_MEAN_V': 'paper',
    'BranchPoint': 'continuation',
    'CONTROL_WEIGHT': 'lqr',
    'CYCLE_CODES': 'orbit',
    'Cycle': 'orbit',
    'DEFAULT_CONFIG': 'paperconfig',
    'DEFAULT_DATA': 'paperconfig',
    'DELTA_COMPLEX_UNTIL': 'paper',
    'DELTA_UNSTABLE_ABOVE': 'paper',
    'Design': 'lqr',
    'EIG_DYNAMIC_GAIN_15': 'paper',
    'EIG_DYNAMIC_GAIN_25': 'paper',
    'EPS': 'paper',
    'FrictionNonlinearity': 'describing',
    'GAIN_15_VISCOUS': 'paper',
    'GAIN_23_EXPONENTIAL': 'paper',
    'GAIN_25_DYNAMIC': 'paper',
    'LoopNumbers': 'orbit',
    'MU_C': 'paper',
    'MU_S': 'paper',
    'OMEGA_RANGE': 'describing',
    'Orbit': 'orbit',
    'OrbitError': 'orbit',
    'PaperConfig': 'paperconfig',
    'REDUCED_GAIN_DYNAMIC': 'paper',
    'REPO_ROOT': 'paperconfig',
    'SAME': 'continuation',
    'SHRINK': 'continuation',
    'STATE_WEIGHT': 'lqr',
    'TAU_C_DYNAMIC': 'paper',
    'TAU_C_EXPONENTIAL': 'paper',
    'carry': 'continuation',
    'characteristic_coefficients': 'linearize',
    'closed_form': 'linearize',
    'controllability_matrix': 'lqr',
    'controllable_basis': 'lqr',
    'coulomb_viscous': 'estimation',
    'delayed_system': 'critical_delay',
    'delta_thresholds': 'stability',
    'design': 'lqr',
    'design_report': 'reports',
    'entry_scale': 'orbit',
    'find_orbit': 'orbit',
    'free_entries': 'orbit',
    'friction_estimates': 'reports',
    'friction_loop': 'describing',
    'friction_to_state': 'describing',
    'harmonic_balance': 'describing',
    'hunting_over_delays': 'describing',
    'hunting_over_gain_scales': 'describing',
    'jacobian': 'linearize',
    'load_paper_config': 'paperconfig',
    'load_table5': 'estimation',
    'load_table6': 'estimation',
    'loop_numbers': 'orbit',
    'lqr_gain': 'lqr',
    'parse_continuation': 'continuation',
    'predict_hunting': 'describing',
    'resized': 'orbit',
    'return_map': 'orbit',
    'rhp_root_count': 'stability',
    'routh_first_column': 'stability',
    'sample_step': 'orbit',
    'settle': 'orbit',
    'shoot': 'orbit',
    'shrunk': 'orbit',
    'simulated_cycle': 'orbit',
    'smooth_friction': 'linearize',
    'stability_report': 'reports',
    'static_coefficient': 'estimation',
    'trace': 'continuation',
    'unstable_partners': 'continuation',
}
_MODULES = ['continuation', 'critical_delay', 'describing', 'estimation', 'linearize', 'lqr', 'orbit',
            'paper', 'paperconfig', 'reports', 'stability']

__all__ = sorted(_WHERE) + _MODULES
__getattr__ = lazy_getattr(__name__, _WHERE, _MODULES)
