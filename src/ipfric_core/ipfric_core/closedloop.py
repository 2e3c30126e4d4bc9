"""Offline closed loop: the rig and the controller sampled at 1 kHz, no ROS.

The same sequence the ROS lockstep loop performs: at sample k the encoders read the
rig, the controller computes V_k, the rig integrates [t_k, t_k+1) with V_k held.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .controller import StateFeedback
from .rig import Rig


@dataclass
class Trajectory:
    """Sampled run. Arrays have one row per sample k (t_k = k dt)."""

    t: np.ndarray            # [s]
    state: np.ndarray        # true (x, theta, x', theta') at t_k
    measured: np.ndarray     # encoder (x, theta) at t_k
    voltage: np.ndarray      # V_k commanded for [t_k, t_k+1) [V]
    friction: np.ndarray     # friction force at t_k [N]
    stuck: np.ndarray        # cart held by static friction at t_k
    end_reason: str          # 'duration', 'FALLEN' or 'TRACK_LIMIT'


def run_closed_loop(rig: Rig, controller: StateFeedback, duration: float) -> Trajectory:
    """Run ``duration`` [s] of sampled feedback; stop early when a rig limit is crossed."""
    n = int(round(duration / rig.dt)) + 1
    t, st = np.empty(n), np.empty((n, 4))
    meas, volt = np.empty((n, 2)), np.empty(n)
    fric, stuck = np.empty(n), np.zeros(n, bool)
    reason = 'duration'
    k = 0
    for k in range(n):
        mx, mth = rig.measure()
        v = controller.update(mx, mth)
        tr = rig.truth()
        t[k], meas[k], volt[k] = rig.t, (mx, mth), v
        st[k] = tr['x'], tr['theta'], tr['x_dot'], tr['theta_dot']
        fric[k], stuck[k] = tr['friction_force'], tr['stuck']
        bad = rig.limit_violation()
        if bad:
            reason = bad[0]
            break
        if k < n - 1:
            rig.step(v)
    m = k + 1
    return Trajectory(t[:m], st[:m], meas[:m], volt[:m], fric[:m], stuck[:m], reason)
