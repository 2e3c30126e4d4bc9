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

from ..physics.friction import DYNAMIC, FP_ASYM, bristle_path, friction_forces, friction_vector, static_limit
from ..physics.params import FRICTION_FIELDS, PLANT_FIELDS, FrictionParams
from ..physics.plant import undeclared_forces
from ..physics.rig import PLANT_TRUTH_FIELDS, drive_means, inputs_through

__all__ = ['ParamSpec', 'PARAMS', 'Effect', 'BASE_PARAMS', 'EFFECTS', 'BASE_MODELS', 'lower_bound', 'static_level',
           'effective_input', 'plateaus', 'dwell_profile', 'fitted_friction_vector', 'static_levels', 'position_force',
           'resisting_force']


@dataclass(frozen=True)
class ParamSpec:
    """One quantity identification fits: unit, bounds, typical size (the fit works on value / size),
    what it is."""

    name: str
    unit: str
    lo: float
    hi: float
    typical: float
    doc: str


#: fields whose 0 means "off" and that a fitted effect needs above 0: a saturation level, the motor side
#: and the contact of a drive with play (the scenario's check: > 0 with a drive play)
POSITIVE = ('saturation_V', 'drive_mass_kg', 'drive_stiffness_N_per_m')


def _schema(table: dict, name: str, typical: float) -> ParamSpec:
    """The schema's field ``name`` as a fitted parameter; an open lower bound (a period, a mass) or a field of
    :data:`POSITIVE` starts at 1e-3 of the typical size, the smallest value the fit may try."""
    f = table[name]
    lo = 1e-3 * typical if f.lo_open or name in POSITIVE else float(f.lo)
    return ParamSpec(name, f.unit, lo, float(f.hi), typical, f.doc)


#: every quantity identification fits, each defined once with its bounds: the plant's constants
#: (:data:`~ipfric_core.physics.params.PLANT_FIELDS`), the friction law's levels [N] (F_N = 1) and
#: coefficients (:data:`~ipfric_core.physics.params.FRICTION_FIELDS`), and the undeclared effects under
#: the names of :class:`~ipfric_core.physics.rig.PlantTruth` (:data:`~ipfric_core.physics.rig.PLANT_TRUTH_FIELDS`)
PARAMS: dict[str, ParamSpec] = {p.name: p for p in (
    *(_schema(PLANT_FIELDS, k, v) for k, v in (('M', 0.5), ('m', 0.1), ('l', 0.1), ('alpha', 1.0), ('beta', 5.0))),
    ParamSpec('Fc', 'N', 0.0, 50.0, 0.3, 'Coulomb level mu_c F_N, eq. (6)'),
    ParamSpec('Fs_excess', 'N', -50.0, 50.0, 0.3, 'static minus Coulomb level (mu_s - mu_c) F_N, eq. (5); below 0 '
              'the Stribeck curve rises from the static to the Coulomb level (a friction that grows with speed)'),
    *(_schema(FRICTION_FIELDS, k, v) for k, v in (('eps', 2.0), ('v_s', 0.05), ('sigma0', 1e4), ('sigma1', 1.0))),
    *(_schema(PLANT_TRUTH_FIELDS, k, v) for k, v in (
        ('cogging_sin_N', 0.1), ('cogging_cos_N', 0.1), ('cogging_period_m', 0.01), ('offset_N', 0.1),
        ('asymmetry', 0.2), ('asymmetry_viscous_Ns_per_m', 1.0), ('deadzone_V', 0.1), ('saturation_V', 5.0),
        ('input_delay_s', 0.01), ('input_lag_s', 0.01), ('backlash_m', 1e-3), ('drive_backlash_m', 1e-3),
        ('drive_mass_kg', 0.2), ('drive_stiffness_N_per_m', 1e5), ('drive_damping_Ns_per_m', 20.0),
        ('bias_theta_rad', 0.005))),
)}


@dataclass(frozen=True)
class Effect:
    """A candidate effect: its parameters (names of :data:`PARAMS`; each starts at 0 unless the search
    chooses a start from the data), where it acts, the signature that points to it."""

    name: str
    params: tuple
    acts_on: str          # 'friction', 'force', 'input', 'drive' or 'sensor'
    signature: str        # key of residual.SIGNATURES
    doc: str
    requires: tuple = ()
    needs_theta: bool = False

    @property
    def specs(self) -> list[ParamSpec]:
        return [PARAMS[n] for n in self.params]


#: the equation error's base model: the mass the force balance fits and the viscous slope
BASE_PARAMS = ('M', 'eps')

EFFECTS = {e.name: e for e in (
    Effect('coulomb', ('Fc', 'Fs_excess'), 'friction',
           'velocity_sign', 'Coulomb and static friction, eqs. (4)-(7): Fc sgn(x\') while sliding, the '
           'cart held up to Fs = Fc + Fs_excess (seen at breakaway): the residual jumps across x\' = 0'),
    Effect('stribeck', ('v_s',), 'friction',
           'speed', 'the sliding level falls from Fs to Fc as exp(-(|x\'|/v_s)^2), eq. (8) with gamma = 2: '
           'the residual falls with speed at low |x\'|', requires=('coulomb',)),
    Effect('presliding', ('sigma0', 'sigma1'),
           'friction', 'reversal', 'bristle (dynamic) friction, eqs. (10)-(11): sigma0 z replaces the '
           'sliding level; a transient after each reversal', requires=('coulomb',)),
    Effect('asymmetry', ('asymmetry', 'asymmetry_viscous_Ns_per_m'), 'friction',
           'direction', 'direction-dependent friction, the law of physics.friction: level (1 + asymmetry) forward, '
           '(1 - asymmetry) backward, static included, viscous eps +/- asymmetry_viscous_Ns_per_m; the residual is '
           'even in x\' (the same sign both ways) where friction misfits are odd'),
    Effect('offset', ('offset_N',), 'force', 'mean',
           'a constant force (slope of the track, amplifier offset): the residual has a mean'),
    Effect('cogging', ('cogging_sin_N', 'cogging_cos_N', 'cogging_period_m'), 'force', 'position',
           'position-periodic force (motor cogging, screw ripple) a sin(2 pi x/P) + b cos(2 pi x/P) of '
           'physics.plant: a peak in the spectrum of the residual over position'),
    Effect('backlash', ('backlash_m',), 'sensor', 'reversal',
           'play of width backlash_m between cart and encoder: the measured position dwells at each '
           'reversal while the cart moves across it; spikes of residual right after reversals'),
    Effect('drive_backlash', ('drive_backlash_m', 'drive_mass_kg', 'drive_stiffness_N_per_m', 'drive_damping_Ns_per_m'),
           'drive', 'reversal',
           'play between the motor side of the drive (its mass reflected to the rack) and the cart, the encoder '
           'on the cart, a stiff contact beyond it (physics.simulate.advance_drive): at a reversal of the drive '
           'force the cart coasts while the motor side crosses the play, then takes a knock'),
    Effect('deadzone', ('deadzone_V',), 'input', 'voltage',
           'input deadzone: |u| < dz gives no force, beyond it u - sgn(u) dz; the residual is an odd '
           'step in u'),
    Effect('saturation', ('saturation_V',), 'input', 'voltage',
           'the drive clips |u| at saturation_V: the residual grows with |u| beyond it'),
    Effect('delay', ('input_delay_s',), 'input', 'lag',
           'transport delay between command and force (physics.rig.drive_pieces): the residual correlates '
           'with the input\'s rate at a lag'),
    Effect('lag', ('input_lag_s',), 'input', 'lag',
           'first-order lag between the command and the force (an amplifier, a motor current loop; '
           'physics.rig.lag_response): the force answers a step of the command over input_lag_s'),
    Effect('sensor_bias', ('bias_theta_rad',), 'sensor', 'pendulum_mean',
           'constant angle-encoder offset: the pendulum equation (4/3) l theta\'\' = g sin(theta) - '
           'x\'\' cos(theta) has a mean residual of about g * bias', needs_theta=True),
)}
BASE_MODELS = {
    'viscous': (),
    'coulomb': ('coulomb',),
    'exponential': ('coulomb', 'stribeck'),
    'dynamic': ('coulomb', 'stribeck', 'presliding'),
}


def lower_bound(name: str, active) -> float:
    """The lower bound of parameter ``name`` with the friction parts ``active`` (keys of :data:`EFFECTS`):
    :data:`PARAMS`'s, but 0 for Fs_excess without the stribeck effect: a static level below the Coulomb
    level needs the Stribeck curve to rise from one to the other (eq. 8); the coulomb law holds at least
    its sliding level."""
    return 0.0 if name == 'Fs_excess' and 'stribeck' not in active else PARAMS[name].lo


def static_level(fc: float, excess: float) -> float:
    """Fs = Fc + Fs_excess [N], the static level of eq. (5): at least 0 (a static level fitted to 0 or
    below is refuted: :func:`ipfric_core.ident.refutations.bound_params`)."""
    return max(fc + excess, 0.0)


def effective_input(t: np.ndarray, u: np.ndarray, p: dict, active) -> np.ndarray:
    """u_eff: the input after delay and lag (their mean over each sample interval), deadzone and saturation
    (same unit as u), the rig's law."""
    if 'delay' in active or 'lag' in active:
        u = drive_means(t, u, p['input_delay_s'] if 'delay' in active else 0.0,
                        p['input_lag_s'] if 'lag' in active else 0.0)
    if 'deadzone' in active or 'saturation' in active:
        u = inputs_through(np.ascontiguousarray(u, float), p['deadzone_V'] if 'deadzone' in active else 0.0,
                           p['saturation_V'] if 'saturation' in active else 0.0)
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

    Levels are in N (F_N = 1): mu_c = Fc, mu_s = Fc + Fs_excess (:func:`static_level`), gamma = 2. Without the
    stribeck effect the dynamic law's level stays at Fc. Fc is floored at 1e-9 N, where the
    laws divide by the level.
    """
    asym = ({'asymmetry': p['asymmetry'], 'asymmetry_viscous': p['asymmetry_viscous_Ns_per_m']}
            if 'asymmetry' in active else {})
    if 'coulomb' not in active:
        return friction_vector(FrictionParams(model='viscous', eps=p['eps'], **asym), 1.0)
    fc = max(p['Fc'], 1e-9)
    stribeck = 'stribeck' in active
    if 'presliding' in active:
        law = FrictionParams(model='dynamic', eps=p['eps'], mu_c=fc,
                             mu_s=static_level(fc, p['Fs_excess']) if stribeck else fc,
                             v_s=p['v_s'] if stribeck else 1.0, sigma0=p['sigma0'], sigma1=p['sigma1'], **asym)
    else:
        law = FrictionParams(model='exponential' if stribeck else 'coulomb', eps=p['eps'], mu_c=fc,
                             mu_s=static_level(fc, p['Fs_excess']), v_s=p['v_s'] if stribeck else 1.0, **asym)
    return friction_vector(law, 1.0)


def static_levels(p: dict, active) -> tuple[float, float]:
    """(backward, forward) [N]: the largest force static friction holds against a push backward and
    forward, (1 -/+ a) Fs with the direction dependence of the law (eq. 5 and
    :func:`~ipfric_core.physics.friction.holding_margin`); (0, 0) without the coulomb effect."""
    fp = fitted_friction_vector(p, active)
    limit = static_limit(fp)
    return (1.0 - fp[FP_ASYM]) * limit, (1.0 + fp[FP_ASYM]) * limit


def position_force(x, p: dict, active):
    """Forces fixed to the track or constant (offset, cogging) as resistance [N]: minus the force
    on the cart of :func:`ipfric_core.physics.plant.undeclared_force`. They act at rest too."""
    cog = (p['cogging_sin_N'], p['cogging_cos_N'], p['cogging_period_m']) if 'cogging' in active else (0.0, 0.0, 1.0)
    ef = (*(float(c) for c in cog), float(p['offset_N']) if 'offset' in active else 0.0)
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
