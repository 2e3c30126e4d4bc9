"""Studies of a scenario's sampled closed loop, each varying the scenario: periodic orbits and
their continuation, the edge of the upright's basin, the design check of a gain, sweeps over
the delay and the initial angle, the Monte Carlo over parameter uncertainty, the bifurcation
diagram; locally or on a Dask cluster.

The names below are what a user of the library calls; each is loaded from its module on
first use, so importing the package stays cheap.
"""
from ..lazy import lazy_package

__all__, __getattr__ = lazy_package(__name__, __path__, {
    'variants': ('variant', 'loop_of', 'scenario_at', 'exact_sensors'),
    'outcome': ('classify_run',),
    'orbit': ('find_orbit', 'Orbit'),
    'continuation': ('trace',),
    'basin': ('basin_edge',),
    'check': ('check_scenarios',),
    'sweep': ('threshold_angle',),
    'montecarlo': ('run_montecarlo',),
    'executor': ('make_executor',),
})
