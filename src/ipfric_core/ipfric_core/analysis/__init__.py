"""What a run or a rig recorded, offline: bags and rig logs read back, classification of the
oscillation (settled, limit cycle, irregular, growing, fallen), amplitudes, periods, sticking, figures.

The names below are what a user of the library calls; each is loaded from its module on
first use, so importing the package stays cheap.
"""
from ..lazy import lazy_package

__all__, __getattr__ = lazy_package(__name__, __path__, {
    'bagread': ('read_run', 'RunData'),
    'records': ('load', 'Record'),
    'oscillation': ('classify', 'Oscillation'),
    'recorded_run': ('analyze_run', 'analyze_log', 'overlay_runs'),
})
