"""Design on the physics (paper sections 3-5 and the appendix): linearization, LQR, Routh-Hurwitz,
the critical delay, the describing-function prediction of the hunting, friction estimates
from the appendix tables and the printed numbers.

The names below are what a user of the library calls; each is loaded from its module on
first use, so importing the package stays cheap.
"""
from ..lazy import lazy_package

__all__, __getattr__ = lazy_package(__name__, __path__, {
    'linearize': ('jacobian',),
    'lqr': ('design', 'Design'),
    'stability': ('delta_thresholds',),
    'critical_delay': ('gain_critical_delay',),
    'describing': ('predict_hunting',),
    'paperconfig': ('load_paper_config', 'PaperConfig'),
    'reports': ('design_report', 'stability_report'),
})
