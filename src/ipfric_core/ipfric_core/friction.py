"""Cart-track friction laws (paper section 2, eqs. 3-11). The one place they are defined.

Sign convention: every force returned is the friction force ON the cart [N]; ``v`` is
the cart velocity [m/s]; ``z`` the mean bristle deflection [m] of the dynamic model.

Models (``FrictionParams.model``):

- ``viscous``      F = -eps v                                           eq. (3)
- ``coulomb``      static (5) while stuck; -mu_c F_N sgn(v) - eps v       eqs. (4)-(7)
- ``exponential``  static (5) while stuck; -g(v) sgn(v) - eps v           eq. (8)
- ``dynamic``      F = -(sigma1 + eps) v - sigma0 z (1 - sigma1 |v| / g(v)),
                   z' = v - sigma0 |v| z / g(v)                           eqs. (10)-(11)

with the Stribeck level g(v) = (mu_c + (mu_s - mu_c) exp(-(|v|/v_s)^gamma)) F_N.
With ``smoothing='tanh'`` sgn(v) becomes tanh(delta v) and the law is smooth (no
sticking phase). Sticking itself (the cart at rest while the force static friction
must cancel stays below mu_s F_N) is a property of the motion, handled by
:mod:`ipfric_core.simulate` with :meth:`Friction.holds`.
"""
from __future__ import annotations

import math

from .params import FrictionParams


def stribeck_level(v: float, mu_s: float, mu_c: float, v_s: float, gamma: float,
                   normal_force: float) -> float:
    """g(v) = (mu_c + (mu_s - mu_c) exp(-(|v|/v_s)^gamma)) F_N  [N], eq. (8)."""
    return (mu_c + (mu_s - mu_c) * math.exp(-(abs(v) / v_s) ** gamma)) * normal_force


def static_friction(applied: float, limit: float) -> float:
    """Static friction (eq. 5): cancels ``applied`` [N] up to ``limit`` = mu_s F_N [N]."""
    if abs(applied) < limit:
        return -applied
    return -math.copysign(limit, applied)


class Friction:
    """A friction law with its parameters and the normal force F_N [N].

    Parameters
    ----------
    params : FrictionParams
    normal_force : float
        F_N [N]; (M + m) g with the pendulum on the cart, M g for the cart alone.
    """

    def __init__(self, params: FrictionParams, normal_force: float):
        self.params = params
        self.normal_force = float(normal_force)
        p = params
        self.model = p.model
        self.smooth = p.smoothing == 'tanh'
        #: True when the law has a sticking phase (exact stick-slip).
        self.sticks = p.model in ('coulomb', 'exponential') and not self.smooth
        #: Number of internal friction states (the bristle deflection z).
        self.n_states = 1 if p.model == 'dynamic' else 0
        #: Largest force static friction can hold, mu_s F_N [N] (eq. 5).
        self.static_limit = p.mu_s * self.normal_force if p.model != 'viscous' else 0.0

    def level(self, v: float) -> float:
        """Magnitude of the velocity-dependent sliding friction [N]: mu_c F_N or g(v)."""
        p = self.params
        if p.model == 'viscous':
            return 0.0
        if p.model == 'coulomb':
            return p.mu_c * self.normal_force
        return stribeck_level(v, p.mu_s, p.mu_c, p.v_s, p.gamma, self.normal_force)

    def force(self, v: float, z: float = 0.0, direction: float = 0.0) -> float:
        """Friction force on the moving cart [N].

        ``direction`` (+1 or -1) replaces sgn(v) for the sticking laws, so that a
        step that ends exactly at v = 0 keeps the sign of the motion it integrates.
        """
        p = self.params
        if p.model == 'viscous':
            return -p.eps * v
        if p.model == 'dynamic':
            return -(p.sigma1 + p.eps) * v - p.sigma0 * z * (1.0 - p.sigma1 * abs(v) / self.level(v))
        if self.smooth:
            sign = math.tanh(p.delta * v)
        else:
            sign = direction if direction else math.copysign(1.0, v) if v else 0.0
        return -self.level(v) * sign - p.eps * v

    def z_rate(self, v: float, z: float) -> float:
        """Bristle deflection rate z' [m/s], eq. (10); 0 for the other laws."""
        if self.model != 'dynamic':
            return 0.0
        return v - self.params.sigma0 * abs(v) * z / self.level(v)

    def holds(self, applied: float) -> bool:
        """True when static friction can hold the resting cart against ``applied`` [N]."""
        return abs(applied) < self.static_limit

    def slope_at_rest(self) -> float:
        """d(-F)/dv at v = 0 [N s/m] of the smooth law used for linearization.

        viscous: eps; coulomb/exponential: eps + delta g(0) (tanh smoothing,
        paper section 3.1: eps + delta mu_s (M+m) g); dynamic: sigma1 + eps (the
        sigma0 z term enters through the bristle state).
        """
        p = self.params
        if p.model == 'viscous':
            return p.eps
        if p.model == 'dynamic':
            return p.sigma1 + p.eps
        return p.eps + p.delta * self.level(0.0)
