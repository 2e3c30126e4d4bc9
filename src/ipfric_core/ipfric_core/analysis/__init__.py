"""What a run or a rig recorded, offline: bags and rig logs read back, classification of the
oscillation (settled, limit cycle, irregular, growing, fallen), amplitudes, periods, sticking, figures.

Modules: bagread, oscillation, plots, recorded_run, records.
The names below are what a user of the library calls; each is loaded from its module on
first use, so importing the package stays cheap.
"""
from __future__ import annotations

from ..lazy import lazy_getattr

#: public name -> module that defines it
_WHERE = {
    'read_run': 'bagread',
    'RunData': 'bagread',
    'load': 'records',
    'Record': 'records',
    'classify': 'oscillation',
    'Oscillation': 'oscillation',
    'analyze_run': 'recorded_run',
    'analyze_log': 'recorded_run',
    'overlay_runs': 'recorded_run',
}
_MODULES = ['bagread', 'oscillation', 'plots', 'recorded_run', 'records']
__all__ = sorted(_WHERE)
__getattr__ = lazy_getattr(__name__, _WHERE, _MODULES)
