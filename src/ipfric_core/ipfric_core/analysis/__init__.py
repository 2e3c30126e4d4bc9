"""Recorded runs analysed offline: the MCAP reader, oscillation classes, sweeps, Monte Carlo, plots.

Modules: bagread, montecarlo, oscillation, plots, recorded_run, sweep. Every public name below
is loaded from its module on first use, so importing the package stays cheap."""
from __future__ import annotations

from ..lazy import lazy_getattr

#: public name -> module that defines it
_WHERE = {
    'ABSURD': 'bagread',
    'CHUNK': 'montecarlo',
    'CLASSES': 'oscillation',
    'CLASS_COLOURS': 'plots',
    'COMPRESSIONS': 'bagread',
    'DECODED': 'bagread',
    'DISTRIBUTIONS': 'montecarlo',
    'FIELDS': 'sweep',
    'HUNTING': 'montecarlo',
    'MAGIC': 'bagread',
    'MAX_CHUNK': 'bagread',
    'Oscillation': 'oscillation',
    'PERIOD_SPREAD': 'oscillation',
    'QUANTILES': 'montecarlo',
    'RECORDS': 'bagread',
    'RESULT_FIELDS': 'montecarlo',
    'RESYNC': 'bagread',
    'Regime': 'oscillation',
    'RunData': 'bagread',
    'SCANNED': 'bagread',
    'SENSORS': 'sweep',
    'SPREAD_FIELDS': 'montecarlo',
    'TRUTH_FIELDS': 'bagread',
    'alignment_shift': 'recorded_run',
    'analyze_log': 'recorded_run',
    'analyze_run': 'recorded_run',
    'angle_class': 'sweep',
    'balanced_segments': 'oscillation',
    'boundaries': 'sweep',
    'cell_scenario': 'sweep',
    'classify': 'oscillation',
    'classify_run': 'sweep',
    'classify_samples': 'sweep',
    'clip_to_range': 'montecarlo',
    'count_size': 'recorded_run',
    'crossing_period': 'oscillation',
    'grid': 'sweep',
    'load_cells': 'sweep',
    'loop_timing': 'recorded_run',
    'mcap_file': 'bagread',
    'montecarlo_figure': 'plots',
    'overlay_figure': 'plots',
    'overlay_runs': 'recorded_run',
    'parse_range': 'sweep',
    'parse_spread': 'montecarlo',
    'print_progress': 'sweep',
    'read_run': 'bagread',
    'regimes': 'oscillation',
    'resolution_cell': 'sweep',
    'resolution_figure': 'plots',
    'resolution_study': 'sweep',
    'run_cell': 'sweep',
    'run_chunk': 'montecarlo',
    'run_figure': 'plots',
    'run_montecarlo': 'montecarlo',
    'run_name': 'recorded_run',
    'spectral_period': 'oscillation',
    'spread_draw': 'montecarlo',
    'stability_map': 'plots',
    'summarize': 'montecarlo',
    'threshold_angle': 'sweep',
    'transition_figure': 'plots',
    'true_p2p': 'sweep',
    'write_results': 'montecarlo',
}
_MODULES = ['bagread', 'montecarlo', 'oscillation', 'plots', 'recorded_run', 'sweep']

__all__ = sorted(_WHERE) + _MODULES
__getattr__ = lazy_getattr(__name__, _WHERE, _MODULES)
