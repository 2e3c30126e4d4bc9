"""Studies of a scenario's sampled closed loop, each varying the scenario: periodic orbits and
their continuation, the edge of the upright's basin, the design check of a gain, sweeps over
the delay and the initial angle, the Monte Carlo over parameter uncertainty, the bifurcation
diagram; locally or on a Dask cluster.

Modules: basin, bifurcation, check, check_page, continuation, executor, maps, montecarlo, orbit, orbit_study,
outcome, sweep, variants.
The names below are what a user of the library calls; each is loaded from its module on
first use, so importing the package stays cheap.
"""
from __future__ import annotations

from ..lazy import lazy_getattr

#: public name -> module that defines it
_WHERE = {
    'variant': 'variants',
    'loop_of': 'variants',
    'scenario_at': 'variants',
    'exact_sensors': 'variants',
    'classify_run': 'outcome',
    'find_orbit': 'orbit',
    'Orbit': 'orbit',
    'trace': 'continuation',
    'basin_edge': 'basin',
    'check_scenarios': 'check',
    'threshold_angle': 'sweep',
    'run_montecarlo': 'montecarlo',
    'make_executor': 'executor',
}
_MODULES = ['basin', 'bifurcation', 'check', 'check_page', 'continuation', 'executor', 'maps', 'montecarlo', 'orbit',
            'orbit_study', 'outcome', 'sweep', 'variants']
__all__ = sorted(_WHERE)
__getattr__ = lazy_getattr(__name__, _WHERE, _MODULES)
