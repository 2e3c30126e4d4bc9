"""Design on the physics (paper sections 3-5 and the appendix): linearization, LQR, Routh-Hurwitz,
the critical delay, the describing-function prediction of the hunting, friction estimates
from the appendix tables and the printed numbers.

Modules: critical_delay, describing, estimation, linearize, lqr, paper, paperconfig, reports, stability.
The names below are what a user of the library calls; each is loaded from its module on
first use, so importing the package stays cheap.
"""
from __future__ import annotations

from ..lazy import lazy_getattr

#: public name -> module that defines it
_WHERE = {
    'jacobian': 'linearize',
    'design': 'lqr',
    'Design': 'lqr',
    'delta_thresholds': 'stability',
    'gain_critical_delay': 'critical_delay',
    'predict_hunting': 'describing',
    'load_paper_config': 'paperconfig',
    'PaperConfig': 'paperconfig',
    'design_report': 'reports',
    'stability_report': 'reports',
}
_MODULES = ['critical_delay', 'describing', 'estimation', 'linearize', 'lqr', 'paper', 'paperconfig', 'reports',
            'stability']
__all__ = sorted(_WHERE)
__getattr__ = lazy_getattr(__name__, _WHERE, _MODULES)
