"""The library of candidate effects of a prismatic axis, each a physical model.

The identified force balance of the cart (paper eq. 1 with the motor force 2) is::

    gain * u_eff(t) = M x'' + [pendulum terms] + beta x' + eps x' + R(x, x', t)

u_eff is the input after the input effects (deadzone, saturation, delay); R holds the
friction and the other forces (coulomb, stribeck, presliding, asymmetry, offset,
cogging); drive_backlash cuts the drive from the cart within a play; backlash and
sensor_bias act on the measurements. Every effect has named
parameters with units and bounds, and names the residual signature that points to it
(a variable of :mod:`ipfric_core.ident.residual`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..physics.friction import DYNAMIC, bristle_path, friction_forces, friction_vector
from ..physics.params import FrictionParams
from ..physics.plant import undeclared_forces
from ..physics.rig import inputs_through

__all__ = ['EFFECTS']


@dataclass(frozen=True)
class ParamSpec:
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
    acts_on: str          # 'friction', 'force', 'input', 'drive' or 'sensor'
    signature: str        # key of residual.SIGNATURES
    doc: str
    requires: tuple = ()
    needs_theta: bool = False


BASE_PARAMS = (ParamSpec('mass', 'kg', 1e-3, 1e4, None), ParamSpec('eps', 'N s/m', 0.0, 1e4, 0.0))

EFFECTS = {e.name: e for e in (
    Effect('coulomb', (ParamSpec('Fc', 'N', 0.0, 1e4), ParamSpec('Fs_excess', 'N', 0.0, 1e4)), 'friction',
           'velocity_sign', 'Coulomb and static friction, eqs. (4)-(7): Fc sgn(x\') while sliding, the '
           'cart held up to Fs = Fc + Fs_excess (seen at breakaway): the residual jumps across x\' = 0'),
    Effect('stribeck', (ParamSpec('v_s', 'm/s', 1e-4, 10.0, None),), 'friction',
           'speed', 'the sliding level falls from Fs to Fc as exp(-(|x\'|/v_s)^2), eq. (8) with gamma = 2: '
           'the residual falls with speed at low |x\'|', requires=('coulomb',)),
    Effect('presliding', (ParamSpec('sigma0', 'N/m', 1.0, 1e7, None), ParamSpec('sigma1', 'N s/m', 0.0, 1e5)),
           'friction', 'reversal', 'bristle (dynamic) friction, eqs. (10)-(11): sigma0 z replaces the '
           'sliding level; a transient after each reversal', requires=('coulomb',)),
    Effect('asymmetry', (ParamSpec('asym', '', -0.9, 0.9), ParamSpec('asym_v', 'N s/m', -1e4, 1e4)), 'friction',
           'direction', 'direction-dependent friction, the law of physics.friction: level (1 + asym) forward, '
           '(1 - asym) backward, static included, viscous eps + asym_v sgn(x\'); the residual is even in '
           'x\' (the same sign both ways) where friction misfits are odd'),
    Effect('offset', (ParamSpec('F0', 'N', -1e4, 1e4),), 'force', 'mean',
           'a constant force (slope of the track, amplifier offset): the residual has a mean'),
    Effect('cogging', (ParamSpec('cog_a', 'N', -1e4, 1e4), ParamSpec('cog_b', 'N', -1e4, 1e4),
                       ParamSpec('cog_period', 'm', 1e-4, 10.0, None)), 'force', 'position',
           'position-periodic force (motor cogging, screw ripple) A sin(2 pi x/P + phi) of physics.plant, '
           'fitted as a sin + b cos (a = A cos phi, b = A sin phi): '
           'a peak in the spectrum of the residual over position'),
    Effect('backlash', (ParamSpec('gap', 'm', 0.0, 0.05),), 'sensor', 'reversal',
           'play of width gap between cart and encoder: the measured position dwells at each '
           'reversal while the cart moves gap; spikes of residual right after reversals'),
    Effect('drive_backlash', (ParamSpec('drive_gap', 'm', 0.0, 0.05), ParamSpec('drive_mass', 'kg', 1e-3, 10.0, None),
                              ParamSpec('drive_stiffness', 'N/m', 1e3, 1e6, None),
                              ParamSpec('drive_damping', 'N s/m', 0.0, 1e3, None)), 'drive', 'reversal',
           'play of width drive_gap between the motor side of the drive (mass drive_mass reflected to '
           'the rack) and the cart, the encoder on the cart, a stiff contact beyond it '
           '(physics.simulate.advance_drive): at a reversal of the drive force the cart coasts while '
           'the motor side crosses the play, then takes a knock'),
    Effect('deadzone', (ParamSpec('dz', 'input unit', 0.0, 1e3, None),), 'input', 'voltage',
           'input deadzone: |u| < dz gives no force, beyond it u - sgn(u) dz; the residual is an odd '
           'step in u'),
    Effect('saturation', (ParamSpec('u_max', 'input unit', 1e-6, 1e6, None),), 'input', 'voltage',
           'the drive clips |u| at u_max: the residual grows with |u| beyond it'),
    Effect('delay', (ParamSpec('delay', 's', 0.0, 0.5, None),), 'input', 'lag',
           'transport delay between command and force (or sensor): the residual correlates with '
           'the input\'s rate at a lag'),
    Effect('sensor_bias', (ParamSpec('theta_bias', 'rad', -0.3, 0.3),), 'sensor', 'pendulum_mean',
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


def effective_input(t: np.ndarray, u: np.ndarray, p: dict, active) -> np.ndarray:
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


def fitted_friction_vector(p: dict, active) -> tuple:
    """The identified friction as the parameter vector of :mod:`ipfric_core.physics.friction`
    (:func:`~ipfric_core.physics.friction.friction_vector` of the law's FrictionParams).

    Levels are in N (F_N = 1): mu_c = Fc, mu_s = Fc + Fs_excess, gamma = 2. Without the
    stribeck effect the dynamic law's level stays at Fc. Fc is floored at 1e-9 N, where the
    laws divide by the level.
    """
    asym = {'asymmetry': p['asym'], 'asymmetry_viscous': p['asym_v']} if 'asymmetry' in active else {}
    if 'coulomb' not in active:
        return friction_vector(FrictionParams(model='viscous', eps=p['eps'], **asym), 1.0)
    fc = max(p['Fc'], 1e-9)
    stribeck = 'stribeck' in active
    if 'presliding' in active:
        law = FrictionParams(model='dynamic', eps=p['eps'], mu_c=fc, mu_s=fc + p['Fs_excess'] if stribeck else fc,
                             v_s=p['v_s'] if stribeck else 1.0, sigma0=p['sigma0'], sigma1=p['sigma1'], **asym)
    else:
        law = FrictionParams(model='exponential' if stribeck else 'coulomb', eps=p['eps'], mu_c=fc,
                             mu_s=fc + p['Fs_excess'], v_s=p['v_s'] if stribeck else 1.0, **asym)
    return friction_vector(law, 1.0)


def static_level(p: dict, active) -> float:
    """Fs [N]: the largest force static friction holds (0 without the coulomb effect), eq. (5)."""
    return p['Fc'] + p['Fs_excess'] if 'coulomb' in active else 0.0


def position_force(x, p: dict, active):
    """Forces fixed to the track or constant (offset, cogging) as resistance [N]: minus the force
    on the cart of :func:`ipfric_core.physics.plant.undeclared_force`. They act at rest too."""
    amp, phase, period = 0.0, 0.0, 1.0
    if 'cogging' in active:
        amp, phase, period = np.hypot(p['cog_a'], p['cog_b']), np.arctan2(p['cog_b'], p['cog_a']), p['cog_period']
    ef = (float(amp), float(period), float(phase), float(p['F0']) if 'offset' in active else 0.0)
    return -undeclared_forces(ef, np.ascontiguousarray(x, float))   # resisting: minus the force on the cart


def resisting_force(x, v, p: dict, active, dt: float) -> np.ndarray:
    """R [N]: the force the drive must supply against friction and the other forces.

    The friction (viscous, coulomb, stribeck, presliding) is the law of
    :mod:`ipfric_core.physics.friction`, with the bristle state integrated along v.
    """
    v = np.ascontiguousarray(v, float)
    fp = fitted_friction_vector(p, active)
    z = bristle_path(fp, v, dt) if fp[0] == DYNAMIC else np.zeros_like(v)
    return -friction_forces(fp, v, z) + position_force(x, p, active)
