"""Nonlinear cart-pendulum, paper eq. (1) with the motor force (2), first-order form (16).

State (SI): s = (x [m], theta [rad from upright], x' [m/s], theta' [rad/s]) and, for the
dynamic friction model, z [m] (bristle deflection) as a fifth entry.
"""
from __future__ import annotations

import math

from .friction import Friction
from .params import FrictionParams, PlantParams


class CartPendulum:
    """Equations of motion of the rig with a given friction law.

    Parameters
    ----------
    plant : PlantParams
    friction : FrictionParams
    normal_force : float, optional
        F_N [N] for the friction law; default (M + m) g as in the paper.
    """

    def __init__(self, plant: PlantParams, friction: FrictionParams,
                 normal_force: float | None = None):
        self.p = plant
        fn = plant.normal_force if normal_force is None else normal_force
        self.friction = Friction(friction, fn)
        self.n_states = 4 + self.friction.n_states

    def motor_force(self, voltage: float, x_dot: float) -> float:
        """F = alpha V - beta x' [N], eq. (2)."""
        return self.p.alpha * voltage - self.p.beta * x_dot

    def accelerations(self, theta: float, theta_dot: float, force: float) -> tuple[float, float]:
        """(x'', theta'') from eq. (16) for a total horizontal force on the cart [N].

        ``force`` = F + F_fric (+ any extra force on the cart).
        """
        p = self.p
        s, c = math.sin(theta), math.cos(theta)
        den = p.M + p.m - 0.75 * p.m * c * c
        xdd = (force + p.m * p.l * s * theta_dot ** 2 - 0.75 * p.m * p.g * c * s) / den
        thdd = (-force * c - p.m * p.l * s * c * theta_dot ** 2 + (p.M + p.m) * p.g * s) / (
            (4.0 / 3.0) * p.l * den)
        return xdd, thdd

    def held_force(self, theta: float, theta_dot: float, force: float) -> float:
        """Force static friction must cancel to keep the cart at rest [N] (eq. 5's F_applied).

        With x'' = 0, eq. (1) gives theta'' = 3 g sin(theta) / (4 l) and the horizontal
        force on the resting cart is ``force`` + m l sin(theta) theta'^2 - m l cos(theta)
        theta''; it includes the pendulum's reaction.
        """
        p = self.p
        s, c = math.sin(theta), math.cos(theta)
        return force + p.m * p.l * s * theta_dot ** 2 - 0.75 * p.m * p.g * c * s

    def stuck_theta_acceleration(self, theta: float) -> float:
        """theta'' [rad/s^2] while the cart is held at rest: 3 g sin(theta) / (4 l)."""
        return 0.75 * self.p.g * math.sin(theta) / self.p.l

    def derivative(self, state, voltage: float, direction: float = 0.0,
                   extra_force: float = 0.0) -> list[float]:
        """ds/dt of the sliding (or smooth) motion, eq. (16) with (17) and the friction law.

        ``direction`` fixes sgn(x') of a sticking law over a step; ``extra_force`` [N]
        is added on the cart (effects the model does not declare).
        """
        x_dot, theta, theta_dot = state[2], state[1], state[3]
        z = state[4] if self.n_states == 5 else 0.0
        f = self.motor_force(voltage, x_dot) + self.friction.force(x_dot, z, direction) + extra_force
        xdd, thdd = self.accelerations(theta, theta_dot, f)
        out = [x_dot, theta_dot, xdd, thdd]
        if self.n_states == 5:
            out.append(self.friction.z_rate(x_dot, z))
        return out
