"""The library of candidate effects of a prismatic axis, each a physical model.

The identified force balance of the cart (paper eq. 1 with the motor force 2) is::

    gain * u_eff(t) = M x'' + [pendulum terms] + beta x' + eps x' + R(x, x', t)

u_eff is the input after the input effects (deadzone, saturation, delay); R holds the
friction and the other forces (coulomb, stribeck, presliding, asymmetry, offset,
cogging); backlash and sensor_bias act on the measurements. Every effect has named
parameters with units and bounds, and names the residual signature that points to it
(a variable of :mod:`ipfric_core.ident.residual`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..physics.friction import COULOMB, DYNAMIC, EXPONENTIAL, VISCOUS, bristle_path, friction_forces
from ..physics.rig import inputs_through


@dataclass(frozen=True)
class Param:
    """One parameter: unit, bounds and start value (``None`` = chosen from the data)."""

    name: str
    unit: str
    lo: float
    hi: float
    init: float | None = 0.0


@dataclass(frozen=True)
class Effect:
    """A candidate effect: parameters, where it acts, the signature that points to it."""

    name: str
    params: tuple
    acts_on: str          # 'friction', 'force', 'input' or 'sensor'
    signature: str        # key of residual.SIGNATURES
    doc: str
    requires: tuple = ()
    needs_theta: bool = False


BASE_PARAMS = (Param('mass', 'kg', 1e-3, 1e4, None), Param('eps', 'N s/m', -1e4, 1e4, 0.0))

EFFECTS = {e.name: e for e in (
    Effect('coulomb', (Param('Fc', 'N', 0.0, 1e4), Param('Fs_excess', 'N', 0.0, 1e4)), 'friction',
           'velocity_sign', 'Coulomb and static friction, eqs. (4)-(7): Fc sgn(x\') while sliding, the '
           'cart held up to Fs = Fc + Fs_excess (seen at breakaway): the residual jumps across x\' = 0'),
    Effect('stribeck', (Param('v_s', 'm/s', 1e-4, 10.0, None),), 'friction',
           'speed', 'the sliding level falls from Fs to Fc as exp(-(|x\'|/v_s)^2), eq. (8) with gamma = 2: '
           'the residual falls with speed at low |x\'|', requires=('coulomb',)),
    Effect('presliding', (Param('sigma0', 'N/m', 1.0, 1e7, None), Param('sigma1', 'N s/m', 0.0, 1e5)),
           'friction', 'reversal', 'bristle (dynamic) friction, eqs. (10)-(11): sigma0 z replaces the '
           'sliding level; a transient after each reversal', requires=('coulomb',)),
    Effect('asymmetry', (Param('dFc', 'N', -1e4, 1e4), Param('dFv', 'N s/m', -1e4, 1e4)), 'friction',
           'direction', 'direction-dependent friction: Coulomb Fc + dFc forward, Fc - dFc backward '
           '(a constant force while sliding) and viscous eps + dFv sgn(x\'); the residual is even in '
           'x\' (the same sign both ways) where friction misfits are odd'),
    Effect('offset', (Param('F0', 'N', -1e4, 1e4),), 'force', 'mean',
           'a constant force (slope of the track, amplifier offset): the residual has a mean'),
    Effect('cogging', (Param('cog_sin', 'N', -1e4, 1e4), Param('cog_cos', 'N', -1e4, 1e4),
                       Param('cog_period', 'm', 1e-4, 10.0, None)), 'force', 'position',
           'position-periodic force (motor cogging, screw ripple) a sin(2 pi x/P) + b cos(2 pi x/P): '
           'a peak in the spectrum of the residual over position'),
    Effect('backlash', (Param('gap', 'm', 0.0, 0.05),), 'sensor', 'reversal',
           'play of width gap between cart and encoder: the measured position dwells at each '
           'reversal while the cart moves gap; spikes of residual right after reversals'),
    Effect('deadzone', (Param('dz', 'input unit', 0.0, 1e3, None),), 'input', 'voltage',
           'input deadzone: |u| < dz gives no force, beyond it u - sgn(u) dz; the residual is an odd '
           'step in u'),
    Effect('saturation', (Param('u_max', 'input unit', 1e-6, 1e6, None),), 'input', 'voltage',
           'the drive clips |u| at u_max: the residual grows with |u| beyond it'),
    Effect('delay', (Param('delay', 's', 0.0, 0.5, None),), 'input', 'lag',
           'transport delay between command and force (or sensor): the residual correlates with '
           'the input\'s rate at a lag'),
    Effect('sensor_bias', (Param('theta_bias', 'rad', -0.3, 0.3),), 'sensor', 'pendulum_mean',
           'constant angle-encoder offset: the pendulum equation (4/3) l theta\'\' = g sin(theta) - '
           'x\'\' cos(theta) has a mean residual of about g * bias', needs_theta=True),
)}
BASE_MODELS = {
    'viscous': (),
    'coulomb': ('coulomb',),
    'exponential': ('coulomb', 'stribeck'),
    'dynamic': ('coulomb', 'stribeck', 'presliding'),
}


def shifted(t: np.ndarray, u: np.ndarray, delay: float) -> np.ndarray:
    """u(t - delay) by linear interpolation, held at u[0] before the start."""
    if delay == 0.0:
        return u
    return np.interp(t - delay, t, u, left=u[0])


def input_effects(t: np.ndarray, u: np.ndarray, p: dict, active) -> np.ndarray:
    """u_eff: the input after delay, deadzone and saturation (same unit as u), the rig's law."""
    if 'delay' in active:
        u = shifted(t, u, p['delay'])
    if 'deadzone' in active or 'saturation' in active:
        u = inputs_through(np.ascontiguousarray(u, float), p['dz'] if 'deadzone' in active else 0.0,
                           p['u_max'] if 'saturation' in active else 0.0)
    return u


def plateaus(t: np.ndarray, x: np.ndarray, min_duration: float) -> list[tuple[int, int]]:
    """(first, last) sample of each stretch where the encoder x stays put >= ``min_duration`` [s]."""
    moves = np.nonzero(np.diff(x) != 0.0)[0]
    starts = np.concatenate([[0], moves + 1])
    ends = np.concatenate([moves, [len(x) - 1]])
    return [(int(a), int(b)) for a, b in zip(starts, ends) if t[b] - t[a] >= min_duration]


def dwell_profile(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """D(t) in [-1, 1] with x_true = x_meas + gap/2 D for a play of width gap.

    D is the direction of the last motion; over a plateau of x between motions in
    opposite directions (a reversal: the encoder waits while the cart crosses the gap)
    it goes from the old to the new direction as 1 - 2 tau^2 (the cart starts from rest).
    """
    dx = np.diff(x)
    moves = np.nonzero(dx != 0.0)[0]
    D = np.zeros(len(x))
    if len(moves) < 2:
        return D
    direc = np.sign(dx[moves])
    D[moves[0] + 1:] = direc[0]
    for (i, di), (j, dj) in zip(zip(moves[:-1], direc[:-1]), zip(moves[1:], direc[1:])):
        # x[i+1] ... x[j] is a plateau; motion resumes at j -> j+1
        if dj == di:
            D[i + 1:j + 1] = di
        else:
            tau = (t[i + 1:j + 2] - t[i + 1]) / max(t[j + 1] - t[i + 1], 1e-12)
            D[i + 1:j + 2] = di * (1.0 - 2.0 * tau ** 2)
    D[moves[-1] + 1:] = direc[-1]
    return D


def friction_vector(p: dict, active) -> tuple:
    """The identified friction as the parameter vector of :mod:`ipfric_core.physics.friction`.

    (model code, smoothing, eps, mu_s, mu_c, v_s, gamma, sigma0, sigma1, delta, F_N), see
    :func:`ipfric_core.physics.friction.parameter_vector`. Levels are in N (F_N = 1): mu_c = Fc, mu_s = Fc + Fs_excess, gamma = 2. Without the
    stribeck effect the dynamic law's level stays at Fc. Fc is floored at 1e-9 N, where
    the laws divide by the level.
    """
    if 'coulomb' not in active:
        return (VISCOUS, 0.0, p['eps'], 0.0, 0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 1.0)
    fc = max(p['Fc'], 1e-9)
    stribeck = 'stribeck' in active
    if 'presliding' in active:
        model, fs = DYNAMIC, fc + p['Fs_excess'] if stribeck else fc
    else:
        model, fs = (EXPONENTIAL if stribeck else COULOMB), fc + p['Fs_excess']
    return (model, 0.0, p['eps'], fs, fc, p['v_s'] if stribeck else 1.0, 2.0,
            p.get('sigma0', 0.0), p.get('sigma1', 0.0), 0.0, 1.0)


def static_level(p: dict, active) -> float:
    """Fs [N]: the largest force static friction holds (0 without the coulomb effect), eq. (5)."""
    return p['Fc'] + p['Fs_excess'] if 'coulomb' in active else 0.0


def position_force(x, p: dict, active):
    """Forces fixed to the track or constant [N] (offset, cogging): they act at rest too."""
    r = np.zeros_like(np.asarray(x, float))
    if 'offset' in active:
        r = r + p['F0']
    if 'cogging' in active:
        ph = 2 * np.pi * x / p['cog_period']
        r = r + p['cog_sin'] * np.sin(ph) + p['cog_cos'] * np.cos(ph)
    return r


def resisting_force(x, v, p: dict, active, dt: float) -> np.ndarray:
    """R [N]: the force the drive must supply against friction and the other forces.

    The friction (viscous, coulomb, stribeck, presliding) is the law of
    :mod:`ipfric_core.physics.friction`, with the bristle state integrated along v.
    """
    v = np.ascontiguousarray(v, float)
    fp = friction_vector(p, active)
    z = bristle_path(fp, v, dt) if fp[0] == DYNAMIC else np.zeros_like(v)
    r = -friction_forces(fp, v, z)
    if 'asymmetry' in active:
        speed = np.abs(v)
        r = r + p['dFc'] * (speed > 0) + p['dFv'] * speed
    return r + position_force(x, p, active)
