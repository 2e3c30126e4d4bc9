"""The outcome of one offline run of a scenario: its class, amplitudes and period.

A run of the compiled closed loop (:func:`ipfric_core.physics.closedloop.run_closed_loop`)
judged by :func:`ipfric_core.analysis.oscillation.classify` on the encoder readings, with the
scenario's encoder counts and fallen angle; the sweeps, the Monte Carlo, the bifurcation
diagram and the closed-loop redesign judge runs this one way.
"""
from __future__ import annotations

import numpy as np

from ..analysis.oscillation import Oscillation, classify
from ..constants import DURATION
from ..physics.closedloop import Trajectory, run_closed_loop
from ..run.scenario import Scenario

__all__ = ['classify_samples', 'classify_run', 'true_p2p']


def classify_samples(scn: Scenario, t, x, theta, fell: bool, window: float = 10.0) -> Oscillation:
    """:func:`classify` with the scenario's encoder counts and fallen angle."""
    return classify(t, x, theta, (scn.sim.cart_resolution, scn.sim.angle_resolution), scn.sim.fallen_angle,
                    ended_fallen=fell, window=window)


def classify_run(scn: Scenario, duration: float, window: float = 10.0) -> tuple[Oscillation, Trajectory]:
    """Run ``scn`` offline for ``duration`` [s]; (its Oscillation from the measured positions, the Trajectory)."""
    tr = run_closed_loop(scn.make_rig(), scn.make_controller(), duration)
    return classify_samples(scn, tr.t, tr.measured[:, 0], tr.measured[:, 1], tr.end_reason != DURATION,
                            window), tr


def true_p2p(o: Oscillation, tr: Trajectory) -> tuple[float, float]:
    """Peak-to-peak of the true cart position [m] and angle [rad] of the Trajectory ``tr`` over the
    window its Oscillation ``o`` was judged on (the measured ones are in encoder counts)."""
    w = tr.t >= tr.t[-1] - o.window[1] + o.window[0]
    return float(np.ptp(tr.state[w, 0])), float(np.ptp(tr.state[w, 1]))
