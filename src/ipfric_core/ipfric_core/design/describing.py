"""Describing-function prediction of the hunting: the limit cycle of friction and feedback.

The loop is broken at the friction nonlinearity, as in a control engineer's harmonic balance:

- **Nonlinearity** (paper eq. 8 without its viscous term): the friction force on the cart is
  f = -Phi(x') - eps x', with Phi(v) = g(v) sgn(v) and the Stribeck level
  g(v) = (mu_c + (mu_s - mu_c) exp(-(|v|/v_s)^gamma)) F_N (coulomb: g = mu_c F_N; with tanh
  smoothing tanh(delta v) for sgn v). Phi is odd and static, so its describing function is
  real: N(a) = (4 / (pi a)) int_0^{pi/2} Phi(a sin phi) sin phi dphi for x' = a sin(w t)
  (relay, g = F_c: N = 4 F_c / (pi a); gamma = 2: a Dawson function). Sticking (eq. 5) is
  not in the describing function: the cart is taken to slide through v = 0.
- **Linear part**: the cart-pendulum linearized at the upright (eq. 16, the closed forms of
  :func:`ipfric_core.design.linearize.closed_form` with c = beta + eps), the motor force
  alpha V (eq. 2) with V = K s(t - tau) (eqs. 13, 26) and the friction force f as a second
  input on the cart, b_f = B / alpha:
  s' = A s + B K s(t - tau) + b_f f, so that from f to the state
  S(jw) = (jw I - A - B K(jw) e^{-jw tau})^{-1} b_f, and H(jw) = S_3(jw) (f -> x').
  K(jw) filters the velocity gains by 1 / (1 + jw / w_c) when a velocity filter corner
  ``cutoff_hz`` is given (the controller's estimate, :mod:`ipfric_core.physics.controller`).
- **Harmonic balance**: H(jw) N(a) = -1. N is real and positive, so -1/N(a) runs along the
  negative real axis: a cycle sits where the Nyquist curve of H crosses it (Im H = 0,
  Re H < 0), with N(a) = -1 / Re H(jw). The velocity amplitude a gives the cart amplitude
  a |S_1 / S_3| = a / w and the angle amplitude a |S_2 / S_3|; period 2 pi / w.

The describing function is evaluated by ``control.describing_function`` (python-control) on
:class:`FrictionNonlinearity`, whose exact quadrature of the law of
:mod:`ipfric_core.physics.friction` replaces the sampled one. Inputs are the physics
parameters and plain arrays; nothing here knows a scenario.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import control
import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq

from ..physics.friction import friction_force, friction_vector
from ..physics.params import FrictionParams, PlantParams
from .linearize import closed_form

__all__ = ['friction_loop', 'predict_hunting', 'hunting_over_delays', 'hunting_over_gain_scales']

#: frequencies searched for crossings of the negative real axis [rad/s]
OMEGA_RANGE = (1e-2, 300.0)
#: velocity amplitudes bracketing the harmonic balance [m/s]
AMPLITUDE_RANGE = (1e-9, 1e3)


class FrictionNonlinearity(control.DescribingFunctionNonlinearity):
    """Phi(v) = -(F(v) + eps v) [N]: the friction law of ``friction`` (eq. 8, coulomb or
    exponential, sgn or tanh) without its viscous term, for x' = v [m/s]; F_N = ``normal_force`` [N]."""

    def __init__(self, friction: FrictionParams, normal_force: float):
        super().__init__()
        if friction.model not in ('viscous', 'coulomb', 'exponential'):
            raise ValueError(f'friction.model: {friction.model!r} has an internal state; the describing '
                             f'function here is of a static law: viscous, coulomb or exponential')
        self.fp = friction_vector(friction.replace(asymmetry=0.0, asymmetry_viscous=0.0), normal_force)
        self.eps = friction.eps

    def __call__(self, v):
        v = float(np.squeeze(v))
        return -friction_force(self.fp, v, 0.0, 0.0) - self.eps * v

    def _isstatic(self):
        return True

    def describing_function(self, a):
        """N(a) = (4 / (pi a)) int_0^{pi/2} Phi(a sin phi) sin phi dphi [N s/m], a [m/s] > 0."""
        a = float(a)
        if a <= 0:
            raise ValueError(f'amplitude {a!r}: must be > 0')
        integral, _ = quad(lambda phi: self(a * math.sin(phi)) * math.sin(phi), 0.0, 0.5 * math.pi,
                           epsabs=0.0, epsrel=1e-10, limit=200)
        return 4.0 * integral / (math.pi * a)


def harmonic_balance(response: Callable[[np.ndarray], np.ndarray], nonlinearity,
                     omega: np.ndarray) -> list[tuple[float, float]]:
    """Solutions (a, w) of H(jw) N(a) = -1 for a real, positive, decreasing N.

    ``response``: w [rad/s] (array) -> H(jw); ``nonlinearity``: evaluated by
    ``control.describing_function``; ``omega``: grid on which the crossings of the negative
    real axis are bracketed (then refined). Sorted by frequency; empty: no intersection.
    """
    h = response(omega)
    found = []
    for i in np.nonzero(np.sign(h.imag[:-1]) * np.sign(h.imag[1:]) < 0)[0]:
        w = brentq(lambda ww: response(np.array([ww]))[0].imag, omega[i], omega[i + 1], xtol=1e-12)
        re = response(np.array([w]))[0].real
        if re >= 0:
            continue
        target = -1.0 / re

        def gap(u, target=target):
            return float(np.real(control.describing_function(nonlinearity, math.exp(u)))) - target
        lo, hi = (math.log(v) for v in AMPLITUDE_RANGE)
        if gap(lo) * gap(hi) > 0:
            continue                         # -1/N(a) never reaches this crossing
        found.append((math.exp(brentq(gap, lo, hi, xtol=1e-12)), float(w)))
    return found


def friction_loop(plant: PlantParams, friction: FrictionParams):
    """(A, B, b_f): the linearized plant with c = beta + eps (section 4.1), the voltage input
    B [per V] and the force input b_f = B / alpha [per N]."""
    A, B = closed_form(plant, FrictionParams(model='viscous', eps=friction.eps))
    return A, B, B / plant.alpha


def friction_to_state(plant: PlantParams, friction: FrictionParams, gain, delay: float, omega,
                      cutoff_hz: float = 0.0) -> np.ndarray:
    """S(jw) (one row per w, columns x, theta, x', theta') from the friction force [N] to the state,
    in the loop V = K(jw) e^{-jw tau} s; gain K [V/m, V/rad, V s/m, V s/rad], delay tau [s]."""
    A, B, bf = friction_loop(plant, friction)
    w = np.atleast_1d(np.asarray(omega, float))
    k = np.asarray(gain, float)[:4]
    filt = 1.0 / (1.0 + 1j * w / (2 * math.pi * cutoff_hz)) if cutoff_hz > 0 else np.ones_like(w)
    kw = np.stack([np.full_like(filt, k[0]), np.full_like(filt, k[1]), k[2] * filt, k[3] * filt], axis=1)
    loop = (B[None, :, :] @ kw[:, None, :]) * np.exp(-1j * w * delay)[:, None, None]
    m = 1j * w[:, None, None] * np.eye(4)[None] - A[None] - loop
    return np.linalg.solve(m, np.broadcast_to(bf, (len(w), 4, 1)))[:, :, 0]


def predict_hunting(plant: PlantParams, friction: FrictionParams, gain, delay: float = 0.0,
                    cutoff_hz: float = 0.0, n_grid: int = 6000) -> dict:
    """The limit cycle the describing function predicts (see the module docstring).

    Returns ``intersection`` False (with ``reason``: 'no intersection') or True with the cycle
    of lowest frequency: ``x_p2p_m`` [m], ``theta_p2p_rad`` [rad], ``period_s`` [s],
    ``omega_rad_s``, ``velocity_amplitude_mps``, ``N`` [N s/m]; ``intersections`` lists every
    (cart p2p [m], period [s]).
    """
    nl = FrictionNonlinearity(friction, plant.normal_force)
    omega = np.geomspace(*OMEGA_RANGE, n_grid)

    def response(w):
        return friction_to_state(plant, friction, gain, delay, w, cutoff_hz)[:, 2]
    cycles = harmonic_balance(response, nl, omega)
    if not cycles:
        return {'intersection': False, 'reason': 'no intersection'}
    rows = []
    for a, w in cycles:
        s = friction_to_state(plant, friction, gain, delay, [w], cutoff_hz)[0]
        rows.append({'x_p2p_m': float(2 * a * abs(s[0] / s[2])), 'theta_p2p_rad': float(2 * a * abs(s[1] / s[2])),
                     'period_s': 2 * math.pi / w, 'omega_rad_s': w, 'velocity_amplitude_mps': a,
                     'N': float(np.real(control.describing_function(nl, a)))})
    return {'intersection': True, **rows[0],
            'intersections': [{'x_p2p_m': r['x_p2p_m'], 'period_s': r['period_s']} for r in rows]}


def hunting_over_delays(plant: PlantParams, friction: FrictionParams, gain, delays: Sequence[float],
                        cutoff_hz: float = 0.0) -> list[dict]:
    """:func:`predict_hunting` at each delay tau [s] (a curve over a bifurcation diagram in tau)."""
    return [{'delay_s': float(t), **predict_hunting(plant, friction, gain, float(t), cutoff_hz)} for t in delays]


def hunting_over_gain_scales(plant: PlantParams, friction: FrictionParams, gain, scales: Sequence[float],
                             delay: float = 0.0, cutoff_hz: float = 0.0) -> list[dict]:
    """:func:`predict_hunting` with the gain multiplied by each scale (a curve over the gain)."""
    k = np.asarray(gain, float)
    return [{'gain_scale': float(c), **predict_hunting(plant, friction, c * k, delay, cutoff_hz)} for c in scales]
