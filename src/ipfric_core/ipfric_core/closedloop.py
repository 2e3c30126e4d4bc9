"""Offline closed loop: plant, encoders and controller sampled at 1 kHz, no ROS.

The same sequence the ROS lockstep loop performs: at sample k the encoders read the
plant, the controller computes V_k, the plant integrates [t_k, t_k+1) with V_k held.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .controller import StateFeedback
from .encoder import quantize
from .simulate import Simulator


@dataclass
class Limits:
    """Safety limits of the rig: track half-length [m], fallen angle [rad]."""

    track: float = 0.4
    fallen: float = math.radians(30.0)


@dataclass
class Trajectory:
    """Sampled run. Arrays have one row per sample k (t_k = k dt)."""

    t: np.ndarray            # [s]
    state: np.ndarray        # true (x, theta, x', theta'[, z]) at t_k
    measured: np.ndarray     # encoder (x, theta) at t_k
    voltage: np.ndarray      # V_k held on [t_k, t_k+1) [V]
    friction: np.ndarray     # friction force at t_k [N]
    stuck: np.ndarray        # cart held by static friction at t_k
    end_reason: str          # 'duration', 'fallen' or 'track_limit'


def run_closed_loop(sim: Simulator, controller: StateFeedback, duration: float,
                    resolution=(0.0, 0.0), limits: Limits | None = None) -> Trajectory:
    """Run ``duration`` [s] of sampled feedback; stop early when a limit is crossed.

    ``resolution`` = (cart [m], angle [rad]) encoder resolutions (0 = exact).
    """
    limits = limits or Limits()
    dt = controller.dt
    n = int(round(duration / dt)) + 1
    nx = len(sim.state)
    t, st = np.empty(n), np.empty((n, nx))
    meas, volt = np.empty((n, 2)), np.empty(n)
    fric, stuck = np.empty(n), np.zeros(n, bool)
    reason = 'duration'
    k = 0
    for k in range(n):
        s = sim.state
        mx, mth = quantize(s[0], resolution[0]), quantize(s[1], resolution[1])
        v = controller.update(mx, mth)
        t[k], st[k], meas[k], volt[k] = sim.t, s, (mx, mth), v
        fric[k], stuck[k] = sim.friction_force(v), sim.stuck
        if abs(s[1]) > limits.fallen:
            reason = 'fallen'
            break
        if abs(s[0]) > limits.track:
            reason = 'track_limit'
            break
        if k < n - 1:
            sim.step(v, dt)
    m = k + 1
    return Trajectory(t[:m], st[:m], meas[:m], volt[:m], fric[:m], stuck[:m], reason)
