"""Measured data back into the model: the ladder of hypotheses judged by simulation error,
the effect library, the equation-error search for force-input records, the export of the
identified rig and the closed-loop redesign.

Modules: effects, equation_error, excitation, identify, ladder, ladder_report, lsq, model, redesign, report,
residual, shooting, uncertainty.
The names below are what a user of the library calls; each is loaded from its module on
first use, so importing the package stays cheap.
"""
from __future__ import annotations

from ..lazy import lazy_getattr

#: public name -> module that defines it
_WHERE = {
    'identify_record': 'identify',
    'run_ladder': 'ladder',
    'Model': 'model',
    'declared': 'model',
    'load_declared': 'model',
    'EFFECTS': 'effects',
    'export_scenario': 'redesign',
    'close_the_loop': 'redesign',
    'load_report': 'uncertainty',
}
_MODULES = ['effects', 'equation_error', 'excitation', 'identify', 'ladder', 'ladder_report', 'lsq', 'model',
            'redesign', 'report', 'residual', 'shooting', 'uncertainty']
__all__ = sorted(_WHERE)
__getattr__ = lazy_getattr(__name__, _WHERE, _MODULES)
