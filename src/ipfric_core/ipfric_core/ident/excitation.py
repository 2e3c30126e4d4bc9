"""Open-loop identification experiment on the true rig: the cart driven by a multisine.

The cart-alone experiment of an identification: the pendulum is taken off (a 1 mg
stand-in hangs below the cart, its force is negligible and the friction's normal force
is M g), the voltage is a sum of sines, and the rig's encoders and undeclared effects
(:class:`rig.PlantTruth`) apply as in any run.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..analysis.records import Record, trajectory_record
from ..constants import DURATION
from ..physics.closedloop import Trajectory
from ..physics.params import FrictionParams, PlantParams
from ..physics.plant import CartPendulum
from ..physics.rig import PlantTruth, Rig

__all__ = ['MULTISINE', 'multisine', 'cart_alone_run']

#: (amplitude [V], frequency [Hz], phase [rad]) of the default multisine
MULTISINE = ((1.2, 0.4, 0.0), (0.6, 1.1, 1.0), (0.35, 2.7, 2.0), (0.2, 5.3, 0.5))


def multisine(t: np.ndarray, components=MULTISINE, scale: float = 1.0) -> np.ndarray:
    """V(t) = scale * sum A sin(2 pi f t + phi) [V]."""
    return scale * sum(a * np.sin(2 * math.pi * f * t + ph) for a, f, ph in components)


def cart_alone_run(plant: PlantParams, friction: FrictionParams, truth: PlantTruth, duration: float,
                   dt: float = 1e-3, resolution: float = 4.54e-5, scale: float = 1.0) -> Record:
    """Drive the cart alone with the multisine for ``duration`` [s]; the measured record."""
    cart = replace(plant, m=1e-6)
    model = CartPendulum(cart, friction, normal_force=plant.M * plant.g)
    rig = Rig(model, truth, [0.0, math.pi, 0.0, 0.0], dt, (resolution, 0.0))
    n = int(round(duration / dt)) + 1
    t = np.arange(n) * dt
    volts = multisine(t, scale=scale)
    meas = np.empty((n, 2))
    for k in range(n):
        meas[k] = rig.measure()
        if k < n - 1:
            rig.step(float(volts[k]))
    traj = Trajectory(t, np.zeros((n, 4)), meas, volts, np.zeros(n), np.zeros(n, bool), DURATION)
    return trajectory_record('cart-alone multisine', traj, plant, cart_alone=True)


