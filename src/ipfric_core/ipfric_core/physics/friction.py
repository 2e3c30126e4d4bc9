"""Cart-track friction laws (paper section 2, eqs. 3-11). The one place they are defined.

Sign convention: every force returned is the friction force ON the cart [N]; ``v`` is
the cart velocity [m/s]; ``z`` the mean bristle deflection [m] of the dynamic model.

Models (``FrictionParams.model``):

- ``viscous``      F = -eps v                                           eq. (3)
- ``coulomb``      static (5) while stuck; -mu_c F_N sgn(v) - eps v       eqs. (4)-(7)
- ``exponential``  static (5) while stuck; -g(v) sgn(v) - eps v           eq. (8)
- ``dynamic``      F = -(sigma1 + eps) v - sigma0 z (1 - sigma1 |v| / g(v)),
                   z' = v - sigma0 |v| z / g(v)                           eqs. (10)-(11)

with the Stribeck level g(v) = (mu_c + (mu_s - mu_c) exp(-(|v|/v_s)^gamma)) F_N: falling with speed
(mu_s > mu_c, the paper's), or rising from a static level below the Coulomb one (mu_s < mu_c, a
contact whose friction grows with speed; the coulomb law needs mu_s >= mu_c).

Direction dependence (``asymmetry`` a, ``asymmetry_viscous`` dF_v; both 0 in the paper):
the level is (1 + a) g forward and (1 - a) g backward, static friction included, and the
viscous coefficient eps + dF_v forward, eps - dF_v backward: F gains -a g(v) - dF_v |v| while
sliding, and static friction holds -(1 - a) mu_s F_N < F_applied < (1 + a) mu_s F_N. (The dynamic law keeps
the symmetric bristle model and takes only dF_v.)
With ``smoothing='tanh'`` sgn(v) becomes tanh(delta v) and the law is smooth (no
sticking phase). Sticking itself (the cart at rest while the force static friction
must cancel stays below mu_s F_N) is a property of the motion, handled by
:mod:`ipfric_core.physics.simulate` with :func:`holds`.

Each law is written once, as a scalar function of a parameter vector ``fp``
(:func:`friction_vector`) compiled by numba: :class:`Friction` calls these functions
from Python and the compiled integrator and closed loop call the very same ones.
"""
from __future__ import annotations

import math

import numpy as np

from .compiled import compiled
from .params import FrictionParams

__all__ = ['DYNAMIC', 'FP_MODEL', 'FP_EPS', 'FP_SIGMA0', 'FP_SIGMA1', 'FP_ASYM', 'friction_vector', 'sticks',
           'static_limit', 'holding_margin', 'holds', 'sliding_level', 'bristle_level', 'friction_force',
           'steady_deflection', 'sliding_friction', 'bristle_relaxation', 'bristle_rate', 'friction_forces',
           'bristle_path', 'Friction']

#: Codes of the friction models in a parameter vector (floats, so the vector is uniform).
MODEL_CODES = {'viscous': 0.0, 'coulomb': 1.0, 'exponential': 2.0, 'dynamic': 3.0}
VISCOUS, COULOMB, EXPONENTIAL, DYNAMIC = 0.0, 1.0, 2.0, 3.0
#: Positions in the parameter vector ``fp`` of :func:`friction_vector`.
(FP_MODEL, FP_SMOOTH, FP_EPS, FP_MU_S, FP_MU_C, FP_V_S, FP_GAMMA, FP_SIGMA0, FP_SIGMA1, FP_DELTA, FP_FN, FP_ASYM,
 FP_ASYM_V) = range(13)


def friction_vector(params: FrictionParams, normal_force: float) -> tuple:
    """The law as a tuple of 13 floats, the argument ``fp`` of the scalar functions below.

    (model code, tanh smoothing 0/1, eps, mu_s, mu_c, v_s, gamma, sigma0, sigma1, delta, F_N,
    asymmetry a, asymmetry_viscous dF_v).
    """
    p = params
    return (MODEL_CODES[p.model], 1.0 if p.smoothing == 'tanh' else 0.0, float(p.eps), float(p.mu_s),
            float(p.mu_c), float(p.v_s), float(p.gamma), float(p.sigma0), float(p.sigma1), float(p.delta),
            float(normal_force), float(p.asymmetry), float(p.asymmetry_viscous))


@compiled
def stribeck_level(v: float, mu_s: float, mu_c: float, v_s: float, gamma: float,
                   normal_force: float) -> float:
    """g(v) = (mu_c + (mu_s - mu_c) exp(-(|v|/v_s)^gamma)) F_N  [N], eq. (8)."""
    r = abs(v) / v_s
    power = r * r if gamma == 2.0 else r ** gamma
    return (mu_c + (mu_s - mu_c) * math.exp(-power)) * normal_force


def static_friction(applied: float, limit: float) -> float:
    """Static friction (eq. 5): cancels ``applied`` [N] up to ``limit`` = mu_s F_N [N]."""
    if abs(applied) < limit:
        return -applied
    return -math.copysign(limit, applied)


@compiled
def sticks(fp) -> bool:
    """True when the law has a sticking phase: coulomb or exponential without smoothing."""
    return (fp[FP_MODEL] == COULOMB or fp[FP_MODEL] == EXPONENTIAL) and fp[FP_SMOOTH] == 0.0


@compiled
def static_limit(fp) -> float:
    """Largest force static friction can hold, mu_s F_N [N] (eq. 5); 0 for viscous."""
    return 0.0 if fp[FP_MODEL] == VISCOUS else fp[FP_MU_S] * fp[FP_FN]


@compiled
def holding_margin(fp, applied: float) -> float:
    """|F_applied - a mu_s F_N| - mu_s F_N [N]: negative while static friction holds (eq. 5 with
    the direction-dependent limits -(1 - a) mu_s F_N and (1 + a) mu_s F_N)."""
    lim = static_limit(fp)
    return abs(applied - fp[FP_ASYM] * lim) - lim


@compiled
def holds(fp, applied: float) -> bool:
    """True when static friction can hold the resting cart against ``applied`` [N] (eq. 5)."""
    return holding_margin(fp, applied) < 0.0


@compiled
def sliding_level(fp, v: float) -> float:
    """Magnitude of the velocity-dependent sliding friction [N]: 0, mu_c F_N or g(v)."""
    if fp[FP_MODEL] == VISCOUS:
        return 0.0
    if fp[FP_MODEL] == COULOMB:
        return fp[FP_MU_C] * fp[FP_FN]
    return stribeck_level(v, fp[FP_MU_S], fp[FP_MU_C], fp[FP_V_S], fp[FP_GAMMA], fp[FP_FN])


#: the least Stribeck level the bristle equations divide by [N] (a law without any level has bristles
#: that carry no force; the floor keeps eqs. (10)-(11) defined there)
MIN_BRISTLE_LEVEL = 1e-9


@compiled
def bristle_level(fp, v: float) -> float:
    """g(v) of the dynamic law's bristle equations [N]: :func:`sliding_level`, at least MIN_BRISTLE_LEVEL."""
    return max(sliding_level(fp, v), MIN_BRISTLE_LEVEL)


@compiled
def bristle_relaxation(fp, v: float) -> float:
    """The bristles' relaxation rate a = sigma0 |v| / g(v) [1/s] of eq. (10) at speed ``v`` [m/s]
    (z' = v - a z): how fast the deflection settles to :func:`steady_deflection`."""
    return fp[FP_SIGMA0] * abs(v) / bristle_level(fp, v)


@compiled
def friction_force(fp, v: float, z: float, direction: float) -> float:
    """Friction force on the moving cart [N], eqs. (3), (6)-(8), (11).

    ``direction`` (+1 or -1) replaces sgn(v) for the sticking laws, so that a step that
    ends exactly at v = 0 keeps the sign of the motion it integrates; 0 = use sgn(v).
    """
    model = fp[FP_MODEL]
    viscous = -fp[FP_EPS] * v - fp[FP_ASYM_V] * abs(v)
    if model == VISCOUS:
        return viscous
    if model == DYNAMIC:
        return viscous - fp[FP_SIGMA1] * v - fp[FP_SIGMA0] * z * (1.0 - fp[FP_SIGMA1] * abs(v) / bristle_level(fp, v))
    if fp[FP_SMOOTH] != 0.0:
        sign = math.tanh(fp[FP_DELTA] * v)
    elif direction != 0.0:
        sign = direction
    else:
        sign = math.copysign(1.0, v) if v != 0.0 else 0.0
    return -sliding_level(fp, v) * (sign + fp[FP_ASYM]) + viscous


@compiled
def steady_deflection(fp, v: float) -> float:
    """The bristles' deflection [m] in steady sliding at ``v`` [m/s] (eq. 10 with z' = 0:
    z = g(v) sgn(v) / sigma0); 0 for the laws without bristles."""
    if fp[FP_MODEL] != DYNAMIC or v == 0.0:
        return 0.0
    return math.copysign(bristle_level(fp, v), v) / fp[FP_SIGMA0]


@compiled
def sliding_friction(fp, v: float) -> float:
    """Friction force on the cart [N] in steady sliding at ``v`` [m/s] (eqs. 3, 6-8; for the dynamic law
    eq. 11 at :func:`steady_deflection`, where the bristles' damping sigma1 no longer acts)."""
    return friction_force(fp, v, steady_deflection(fp, v), 0.0)


@compiled
def bristle_rate(fp, v: float, z: float) -> float:
    """Bristle deflection rate z' [m/s], eq. (10); 0 for the other laws."""
    if fp[FP_MODEL] != DYNAMIC:
        return 0.0
    return v - fp[FP_SIGMA0] * abs(v) * z / bristle_level(fp, v)


@compiled
def friction_forces(fp, v, z):
    """:func:`friction_force` along sampled velocities ``v`` [m/s] and bristle states ``z`` [m]."""
    out = np.empty(len(v))
    for k in range(len(v)):
        out[k] = friction_force(fp, v[k], z[k], 0.0)
    return out


@compiled
def bristle_path(fp, v, dt: float):
    """Bristle deflection z [m] along velocity samples ``v`` [m/s], each held for ``dt`` [s].

    Eq. (10) with v constant is linear in z, z' = v - a z with a = sigma0 |v| / g(v):
    each step is integrated exactly, z -> z_ss + (z - z_ss) exp(-a dt), z_ss = :func:`steady_deflection`.
    Starts from z = 0; z holds while v = 0.
    """
    z = np.empty(len(v))
    zk = 0.0
    for k in range(len(v)):
        if v[k] != 0.0:
            a = bristle_relaxation(fp, v[k])
            zss = steady_deflection(fp, v[k])
            zk = zss + (zk - zss) * math.exp(-a * dt)
        z[k] = zk
    return z


class Friction:
    """A friction law with its parameters and the normal force F_N [N].

    Parameters
    ----------
    params : FrictionParams
    normal_force : float
        F_N [N]; (M + m) g with the pendulum on the cart, M g for the cart alone.

    The methods evaluate the scalar functions of this module on :attr:`vector`.
    """

    def __init__(self, params: FrictionParams, normal_force: float):
        self.params = params
        self.normal_force = float(normal_force)
        self.model = params.model
        self.smooth = params.smoothing == 'tanh'
        #: The law as the parameter vector of the scalar functions.
        self.vector = friction_vector(params, self.normal_force)
        #: True when the law has a sticking phase (exact stick-slip).
        self.sticks = sticks(self.vector)
        #: Number of internal friction states (the bristle deflection z).
        self.n_states = 1 if params.model == 'dynamic' else 0
        #: Largest force static friction can hold, mu_s F_N [N] (eq. 5).
        self.static_limit = static_limit(self.vector)

    def level(self, v: float) -> float:
        """Magnitude of the velocity-dependent sliding friction [N]: mu_c F_N or g(v)."""
        return sliding_level(self.vector, v)

    def force(self, v: float, z: float = 0.0, direction: float = 0.0) -> float:
        """Friction force on the moving cart [N] (see :func:`friction_force`)."""
        return friction_force(self.vector, v, z, direction)

    def z_rate(self, v: float, z: float) -> float:
        """Bristle deflection rate z' [m/s], eq. (10); 0 for the other laws."""
        return bristle_rate(self.vector, v, z)

    def holds(self, applied: float) -> bool:
        """True when static friction can hold the resting cart against ``applied`` [N]."""
        return holds(self.vector, applied)

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
