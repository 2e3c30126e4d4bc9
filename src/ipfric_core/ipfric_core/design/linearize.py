"""Linearization of the cart-pendulum about the upright equilibrium (paper sections 3-5).

Two independent routes that the tests compare: a central-difference Jacobian of the
nonlinear model (16), and the paper's closed forms (the matrices of sections 3.1, 4.1,
4.2 and eqs. 28-32). A sticking law (coulomb, exponential) is linearized with sgn(v)
replaced by tanh(delta v), as in the paper; the dynamic law gives a 5-state model.
"""
from __future__ import annotations

import numpy as np

from ..physics.friction import Friction
from ..physics.params import FrictionParams, PlantParams
from ..physics.plant import CartPendulum

__all__ = ['jacobian', 'closed_form', 'characteristic_coefficients']


def smooth_friction(friction: FrictionParams) -> FrictionParams:
    """The differentiable version of a friction law: tanh(delta v) for sgn(v)."""
    if friction.model in ('coulomb', 'exponential'):
        return friction.replace(smoothing='tanh')
    return friction


def jacobian(plant: PlantParams, friction: FrictionParams, step: float = 1e-7):
    """(A, B) of s' = A s + B V at the upright equilibrium, by central differences."""
    model = CartPendulum(plant, smooth_friction(friction))
    n = model.n_states
    s0 = np.zeros(n)
    A = np.empty((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = step
        A[:, j] = (np.array(model.derivative(s0 + e, 0.0)) - np.array(model.derivative(s0 - e, 0.0))) / (2 * step)
    B = (np.array(model.derivative(s0, step)) - np.array(model.derivative(s0, -step))) / (2 * step)
    return A, B.reshape(n, 1)


def closed_form(plant: PlantParams, friction: FrictionParams):
    """(A, B) of the paper's closed forms (sections 4.1, 4.2; eqs. 28 and 31 with V = 0).

    With D = 4M + m and c = beta + d(-F_fric)/dv at rest (eps, eps + delta mu_s F_N,
    or sigma1 + eps):
    x''     = (-3 m g theta - 4 c x' + 4 alpha V) / D          (- 4 sigma0 z / D)
    theta'' = (3 (M+m) g theta + 3 c x' - 3 alpha V) / (D l)   (+ 3 sigma0 z / (D l))
    z'      = x'                                               (dynamic model only)
    """
    p = plant
    D = 4 * p.M + p.m
    c = p.beta + Friction(friction, p.normal_force).slope_at_rest()
    n = 5 if friction.model == 'dynamic' else 4
    A = np.zeros((n, n))
    A[0, 2] = A[1, 3] = 1.0
    A[2, 1] = -3 * p.m * p.g / D
    A[2, 2] = -4 * c / D
    A[3, 1] = 3 * (p.M + p.m) * p.g / (D * p.l)
    A[3, 2] = 3 * c / (D * p.l)
    B = np.zeros((n, 1))
    B[2, 0] = 4 * p.alpha / D
    B[3, 0] = -3 * p.alpha / (D * p.l)
    if n == 5:
        A[2, 4] = -4 * friction.sigma0 / D
        A[3, 4] = 3 * friction.sigma0 / (D * p.l)
        A[4, 2] = 1.0
    return A, B


def characteristic_coefficients(plant: PlantParams, friction: FrictionParams, gain) -> np.ndarray:
    """[1, a3, a2, a1, a0] of the closed loop with V = K x, paper eq. (19) or (21).

    For the dynamic model this is the quartic factor of lambda * (quartic) = 0, eq. (21).
    ``gain`` holds k1..k4 (a fifth, z entry is ignored, as in the paper); d_j = alpha k_j.
    """
    p = plant
    D = 4 * p.M + p.m
    d1, d2, d3, d4 = (p.alpha * float(k) for k in list(gain)[:4])
    c = p.beta + Friction(friction, p.normal_force).slope_at_rest()
    s0 = friction.sigma0 if friction.model == 'dynamic' else 0.0
    a3 = (3 * d4 + 4 * p.l * (c - d3)) / (D * p.l)
    a2 = (4 * p.l * s0 - 3 * (p.M + p.m) * p.g + 3 * d2 - 4 * p.l * d1) / (D * p.l)
    a1 = -3 * p.g * (c - d3) / (D * p.l)
    a0 = 3 * (d1 - s0) * p.g / (D * p.l)
    return np.array([1.0, a3, a2, a1, a0])
