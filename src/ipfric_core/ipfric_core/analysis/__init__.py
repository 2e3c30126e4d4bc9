"""Recorded runs analysed offline: the MCAP reader, oscillation classes, sweeps, plots.

Modules: bagread, bifurcation, oscillation, plots, recorded_run, sweep. Every public name below is loaded
from its module on first use, so importing the package stays cheap."""
from __future__ import annotations

from ..lazy import lazy_getattr

#: public name -> module that defines it
_WHERE = {
    'ABSURD': 'bagread',
    'CLASSES': 'oscillation',
    'CLASS_COLOURS': 'bifurcation',
    'COMPRESSIONS': 'bagread',
    'DECODED': 'bagread',
    'FIELDS': 'sweep',
    'MAGIC': 'bagread',
    'MAX_CHUNK': 'bagread',
    'Oscillation': 'oscillation',
    'PERIOD_SPREAD': 'oscillation',
    'RECORDS': 'bagread',
    'RESYNC': 'bagread',
    'Regime': 'oscillation',
    'RunData': 'bagread',
    'SCANNED': 'bagread',
    'SENSORS': 'sweep',
    'TRUTH_FIELDS': 'bagread',
    'alignment_shift': 'recorded_run',
    'analyze_log': 'recorded_run',
    'analyze_run': 'recorded_run',
    'balanced_segments': 'oscillation',
    'boundaries': 'sweep',
    'cell_scenario': 'sweep',
    'classify': 'oscillation',
    'classify_run': 'sweep',
    'classify_samples': 'sweep',
    'count_size': 'recorded_run',
    'crossing_period': 'oscillation',
    'diagram': 'bifurcation',
    'grid': 'sweep',
    'linear_critical_delay': 'bifurcation',
    'load_cells': 'sweep',
    'loop_timing': 'recorded_run',
    'mcap_file': 'bagread',
    'overlay_figure': 'plots',
    'overlay_runs': 'recorded_run',
    'parse_range': 'sweep',
    'print_progress': 'sweep',
    'read_run': 'bagread',
    'regimes': 'oscillation',
    'resolution_cell': 'sweep',
    'resolution_figure': 'plots',
    'resolution_study': 'sweep',
    'run_cell': 'sweep',
    'run_figure': 'plots',
    'run_name': 'recorded_run',
    'simulated_classes': 'bifurcation',
    'spectral_period': 'oscillation',
    'stability_map': 'plots',
    'threshold_angle': 'sweep',
    'transition_figure': 'plots',
}
_MODULES = ['bagread', 'bifurcation', 'oscillation', 'plots', 'recorded_run', 'sweep']

__all__ = sorted(_WHERE) + _MODULES
__getattr__ = lazy_getattr(__name__, _WHERE, _MODULES)
