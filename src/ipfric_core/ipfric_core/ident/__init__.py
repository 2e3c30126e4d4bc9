"""Measured data back into the model: the ladder of hypotheses judged by simulation error,
the effect library, the force balance that starts a force-input record, the free run over a
held-out record, the export of the identified rig and the closed-loop redesign.

The names below are what a user of the library calls; each is loaded from its module on
first use, so importing the package stays cheap.
"""
from ..lazy import lazy_package

__all__, __getattr__ = lazy_package(__name__, __path__, {
    'identify': ('identify_record',),
    'ladder': ('run_ladder',),
    'held_out': ('free_run',),
    'model': ('Model', 'declared', 'load_declared'),
    'effects': ('EFFECTS',),
    'redesign': ('export_scenario', 'close_the_loop'),
    'uncertainty': ('load_report',),
})
