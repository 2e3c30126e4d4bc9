"""Nonlinear cart-pendulum, paper eq. (1) with the motor force (2), first-order form (16).

State (SI): s = (x [m], theta [rad from upright], x' [m/s], theta' [rad/s]) and, for the
dynamic friction model, z [m] (bristle deflection) as a fifth entry.

The equations are written once, as scalar functions compiled by numba on a plant vector
``pp`` = (M, m, l, g, alpha, beta) (:func:`plant_vector`) and the friction vector ``fp``
of :mod:`ipfric_core.physics.friction`; :class:`CartPendulum` and the compiled integrator of
:mod:`ipfric_core.physics.simulate` both call them.
"""
from __future__ import annotations

import math

import numpy as np

from .compiled import compiled
from .friction import Friction, bristle_rate, friction_force
from .params import FrictionParams, PlantParams

__all__ = ['plant_vector', 'motor_force', 'held_force', 'required_forces', 'held_forces', 'pendulum_residuals',
           'stuck_theta_acceleration', 'undeclared_force', 'NO_EXTRA_FORCE', 'motor_side_free', 'drive_contact_force',
           'drive_contact_depth', 'force_input', 'beyond_play',
           'undeclared_forces', 'rates', 'CartPendulum', 'cogging_amplitude_phase']

# Positions in the plant vector.
M, MP, L, G, ALPHA, BETA = range(6)


def plant_vector(plant: PlantParams) -> tuple:
    """(M [kg], m [kg], l [m], g [m/s^2], alpha [N/V], beta [N s/m]) as floats."""
    return tuple(float(v) for v in (plant.M, plant.m, plant.l, plant.g, plant.alpha, plant.beta))


@compiled
def motor_force(pp, voltage: float, x_dot: float) -> float:
    """F = alpha V - beta x' [N], eq. (2)."""
    return pp[ALPHA] * voltage - pp[BETA] * x_dot


@compiled
def accelerations(pp, theta: float, theta_dot: float, force: float):
    """(x'', theta'') from eq. (16) for a total horizontal force on the cart [N]."""
    m, l, g = pp[MP], pp[L], pp[G]
    s, c = math.sin(theta), math.cos(theta)
    den = pp[M] + m - 0.75 * m * c * c
    xdd = (force + m * l * s * theta_dot ** 2 - 0.75 * m * g * c * s) / den
    thdd = (-force * c - m * l * s * c * theta_dot ** 2 + (pp[M] + m) * g * s) / ((4.0 / 3.0) * l * den)
    return xdd, thdd


@compiled
def held_force(pp, theta: float, theta_dot: float, force: float) -> float:
    """Force static friction must cancel to keep the cart at rest [N] (eq. 5's F_applied).

    With x'' = 0, eq. (1) gives theta'' = 3 g sin(theta) / (4 l) and the horizontal
    force on the resting cart is ``force`` + m l sin(theta) theta'^2 - m l cos(theta)
    theta''; it includes the pendulum's reaction.
    """
    m, l = pp[MP], pp[L]
    s, c = math.sin(theta), math.cos(theta)
    return force + m * l * s * theta_dot ** 2 - 0.75 * m * pp[G] * c * s


@compiled
def required_forces(pp, x_ddot, theta, theta_dot):
    """Eq. (16) solved for the force: the horizontal force on the cart [N] (motor, friction and
    any other) that gives the cart acceleration ``x_ddot`` [m/s^2] with the pendulum at ``theta``,
    ``theta_dot``, along sampled arrays (the pendulum obeying its own equation)."""
    m, l, g = pp[MP], pp[L], pp[G]
    out = np.empty(len(x_ddot))
    for k in range(len(x_ddot)):
        s, c = math.sin(theta[k]), math.cos(theta[k])
        out[k] = x_ddot[k] * (pp[M] + m - 0.75 * m * c * c) - m * l * s * theta_dot[k] ** 2 + 0.75 * m * g * c * s
    return out


@compiled
def held_forces(pp, theta, theta_dot, force):
    """:func:`held_force` along sampled arrays [N]."""
    out = np.empty(len(theta))
    for k in range(len(theta)):
        out[k] = held_force(pp, theta[k], theta_dot[k], force[k])
    return out


@compiled
def pendulum_residuals(pp, x_ddot, theta, theta_ddot):
    """m ((4/3) l theta'' - g sin(theta) + x'' cos(theta)) [N] along sampled arrays: the
    pendulum's equation (1) (zero for a pendulum that obeys it)."""
    m, l, g = pp[MP], pp[L], pp[G]
    out = np.empty(len(theta))
    for k in range(len(theta)):
        out[k] = m * ((4.0 / 3.0) * l * theta_ddot[k] - g * math.sin(theta[k]) + x_ddot[k] * math.cos(theta[k]))
    return out


@compiled
def stuck_theta_acceleration(pp, theta: float) -> float:
    """theta'' [rad/s^2] while the cart is held at rest: 3 g sin(theta) / (4 l)."""
    return 0.75 * pp[G] * math.sin(theta) / pp[L]


@compiled
def undeclared_force(ef, x: float, v: float) -> float:
    """Force on the cart [N] fixed to the track, that the friction model does not declare.

    ``ef`` = (a [N], b [N], period P [m], offset F0 [N]): a sin(2 pi x / P) + b cos(2 pi x / P)
    + F0 (motor cogging, screw ripple; a sloped track or an amplifier offset). It acts at rest
    too. ``v`` is unused (the signature of a force law).
    """
    f = 0.0
    if ef[0] != 0.0 or ef[1] != 0.0:
        w = 2 * math.pi * x / ef[2]
        f = ef[0] * math.sin(w) + ef[1] * math.cos(w)
    return f + ef[3]


def cogging_amplitude_phase(a: float, b: float) -> tuple[float, float]:
    """(A [N], phi [rad]) of a sin(w) + b cos(w) = A sin(w + phi)."""
    return math.hypot(a, b), math.atan2(b, a)


NO_EXTRA_FORCE = (0.0, 0.0, 1.0, 0.0)


@compiled
def motor_side_free(pp, mass: float, vb: float, voltage: float, h: float):
    """Motor side of a drive with play over ``h`` [s], ``voltage`` [V] held.

    The motor's rotor and gears reflected to the rack as a mass ``mass`` [kg] driven by the
    motor force of eq. (2) on its own speed: mass vb' = alpha V - beta vb (a contact force F
    held over the step enters as V - F / alpha). Exact solution: it tends to alpha V / beta
    [m/s] with time constant mass / beta [s] (at once for a massless motor side). Returns
    (displacement [m], final speed vb [m/s]).
    """
    alpha, beta = pp[ALPHA], pp[BETA]
    if beta <= 0.0:
        if mass <= 0.0:
            return vb * h, vb
        a = alpha * voltage / mass
        return vb * h + 0.5 * a * h * h, vb + a * h
    v_inf = alpha * voltage / beta
    if mass <= 0.0:
        return v_inf * h, v_inf
    tau = mass / beta
    e = math.exp(-h / tau)
    return v_inf * h + (vb - v_inf) * tau * (1.0 - e), v_inf + (vb - v_inf) * e


@compiled
def force_input(pp):
    """The plant vector ``pp`` with alpha 1 N/V and beta 0: its "voltage" is then the force on the cart [N]
    (a drive's contact in the motor's place, eq. 2)."""
    return (pp[M], pp[MP], pp[L], pp[G], 1.0, 0.0)


@compiled
def beyond_play(dp, d: float) -> bool:
    """Whether the motor side of a drive ``dp`` (:func:`drive_contact_force`) is beyond an edge of its play,
    d = motor side minus cart [m]: in contact, unless it is leaving fast."""
    return abs(d) > 0.5 * dp[0]


@compiled
def drive_contact_force(dp, d: float, dv: float) -> float:
    """Force [N] on the cart from the motor side of a drive with play, ``dp`` = (play [m], motor-side
    mass [kg], contact stiffness k [N/m], contact damping c [N s/m]), d = motor side minus cart [m],
    dv its speed relative to the cart [m/s]: k (d -/+ play/2) + c dv beyond either edge of the play
    (a stiff contact, the usual dead-zone model of a two-mass drive), 0 inside it. A contact only
    pushes: the force never pulls the two together."""
    if not beyond_play(dp, d):
        return 0.0
    half = 0.5 * dp[0]
    if d > 0.0:
        return max(dp[2] * (d - half) + dp[3] * dv, 0.0)
    return min(dp[2] * (d + half) + dp[3] * dv, 0.0)


@compiled
def drive_contact_depth(dp, side: float, force: float) -> float:
    """Motor side minus cart [m] at which a drive's contact on ``side`` (+1 forward, -1 backward), at rest
    relative to the cart, carries ``force`` [N]: :func:`drive_contact_force` inverted (dv = 0), the edge of
    the play plus the compression |F| / k beyond it (the edge itself for a pull, or a contact of no
    stiffness yet: an effect not fitted)."""
    squeeze = max(side * force, 0.0) / dp[2] if dp[2] > 0.0 else 0.0
    return side * (0.5 * dp[0] + squeeze)


@compiled
def undeclared_forces(ef, x):
    """:func:`undeclared_force` along sampled positions ``x`` [m]."""
    out = np.empty(len(x))
    for k in range(len(x)):
        out[k] = undeclared_force(ef, x[k], 0.0)
    return out


@compiled
def rates(pp, fp, ef, s, voltage: float, direction: float):
    """ds/dt of the sliding (or smooth) motion, eq. (16) with (17) and the friction law.

    ``s`` = (x, theta, x', theta', z) (z = 0 unless the law is dynamic); ``direction``
    fixes sgn(x') of a sticking law over a step. Returns the 5 rates.
    """
    x_dot, theta, theta_dot, z = s[2], s[1], s[3], s[4]
    f = (motor_force(pp, voltage, x_dot) + friction_force(fp, x_dot, z, direction)
         + undeclared_force(ef, s[0], x_dot))
    xdd, thdd = accelerations(pp, theta, theta_dot, f)
    return x_dot, theta_dot, xdd, thdd, bristle_rate(fp, x_dot, z)


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
        #: The plant as the parameter vector of the scalar functions.
        self.vector = plant_vector(plant)

    def motor_force(self, voltage: float, x_dot: float) -> float:
        """F = alpha V - beta x' [N], eq. (2)."""
        return motor_force(self.vector, voltage, x_dot)

    def accelerations(self, theta: float, theta_dot: float, force: float) -> tuple[float, float]:
        """(x'', theta'') from eq. (16) for a total horizontal force on the cart [N].

        ``force`` = F + F_fric (+ any extra force on the cart).
        """
        return accelerations(self.vector, theta, theta_dot, force)

    def held_force(self, theta: float, theta_dot: float, force: float) -> float:
        """Force static friction must cancel to keep the cart at rest [N] (:func:`held_force`)."""
        return held_force(self.vector, theta, theta_dot, force)

    def stuck_theta_acceleration(self, theta: float) -> float:
        """theta'' [rad/s^2] while the cart is held at rest: 3 g sin(theta) / (4 l)."""
        return stuck_theta_acceleration(self.vector, theta)

    def derivative(self, state, voltage: float, direction: float = 0.0) -> list[float]:
        """ds/dt of the sliding (or smooth) motion (:func:`rates`), as long as ``state``."""
        s = [float(v) for v in state] + [0.0] * (5 - len(state))
        out = rates(self.vector, self.friction.vector, NO_EXTRA_FORCE, tuple(s), voltage, direction)
        return list(out[:self.n_states])
