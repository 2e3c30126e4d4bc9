"""Identification from measured data: records and their loaders, the effect library, fitting, residual analysis, reports, experiments and the redesign loop.

Modules: effects, excitation, identify, records, redesign, report, residual. Every public name below is loaded from its module on
first use, so importing the package stays cheap."""
from __future__ import annotations

import importlib

#: public name -> module that defines it
_WHERE = {
    'BASE_MODELS': 'effects',
    'BASE_PARAMS': 'effects',
    'BINS': 'residual',
    'BLOCK_S': 'identify',
    'BOOTSTRAP': 'identify',
    'Balance': 'identify',
    'Dithered': 'excitation',
    'EDGE_S': 'identify',
    'EFFECTS': 'effects',
    'Effect': 'effects',
    'Fit': 'identify',
    'MAX_LAG': 'residual',
    'MIN_GAIN_PERCENT': 'identify',
    'MIN_SAMPLES': 'records',
    'MULTISINE': 'excitation',
    'P_VALUE': 'identify',
    'Param': 'effects',
    'Prepared': 'identify',
    'Record': 'records',
    'SIGNATURES': 'residual',
    'STUCK_S': 'identify',
    'TICK_S': 'identify',
    'analyse': 'identify',
    'autocorrelation': 'residual',
    'balance': 'identify',
    'band': 'residual',
    'best_fit': 'identify',
    'best_lag': 'residual',
    'block_test': 'identify',
    'candidate_names': 'identify',
    'cart_alone_run': 'excitation',
    'check_record': 'records',
    'close_the_loop': 'redesign',
    'cross_correlation': 'residual',
    'design_friction': 'redesign',
    'designed_gain': 'redesign',
    'dithered_run': 'excitation',
    'dwell_profile': 'effects',
    'errors': 'identify',
    'eta_squared': 'residual',
    'explained': 'identify',
    'export_scenario': 'redesign',
    'figures': 'report',
    'fit': 'identify',
    'friction_summary': 'report',
    'friction_vector': 'effects',
    'identified_friction': 'redesign',
    'identified_truth': 'redesign',
    'identify_steady': 'identify',
    'input_effects': 'effects',
    'load': 'records',
    'load_bag': 'records',
    'load_csv': 'records',
    'load_emps': 'records',
    'markdown': 'report',
    'multisine': 'excitation',
    'param_specs': 'identify',
    'plateaus': 'effects',
    'position_force': 'effects',
    'position_score': 'residual',
    'position_spectrum': 'residual',
    'residual_vector': 'identify',
    'resisting_force': 'effects',
    'resolved': 'identify',
    'result_dict': 'report',
    'shifted': 'effects',
    'signature_scores': 'residual',
    'starts': 'identify',
    'static_level': 'effects',
    'time_since_reversal': 'residual',
    'total_rms': 'identify',
    'trajectory_record': 'records',
    'whiteness': 'residual',
    'write_csv': 'records',
    'write_report': 'report',
}

__all__ = sorted(_WHERE) + ['effects', 'excitation', 'identify', 'records', 'redesign', 'report', 'residual']


def __getattr__(name: str):
    if name in _WHERE:
        return getattr(importlib.import_module(f'.{_WHERE[name]}', __name__), name)
    if name in __all__:
        return importlib.import_module(f'.{name}', __name__)
    raise AttributeError(f'module {__name__!r} has no attribute {name!r}')
