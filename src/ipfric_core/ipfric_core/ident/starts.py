"""The start values of the ladder's hypotheses: an effect's (several where its error has several minima:
a cogging's from the force balance residual's periodogram, a drive play's from a grid of its error), a
friction law's (Stribeck velocities, bristles) and those the cart's force balance gives the refit and
the plant corrections."""
from __future__ import annotations

import math

import numpy as np
from scipy.signal import lombscargle

from ..analysis.records import Record
from ..physics.params import ConfigError
from .effects import PARAMS
from .model import FRICTION_FITTED, LAW_PARAMS, Model
from .problem import Problem
from .refutations import RIPPLE_PERIODS, response_lag, rest_offset, smallest_moving_command

__all__ = ['DRIVE_GRID', 'effect_starts', 'ripple_starts', 'phased', 'drive_starts', 'law_starts', 'stribeck_starts',
           'peak_level', 'bristle_starts', 'balance_starts', 'contact_damping']


def effect_starts(pr: Problem, model: Model, name: str) -> list[dict]:
    """Start values of effect ``name`` (several where the fit has several minima); a start may
    also name other parameters of ``model``."""
    rec = pr.rec
    if name == 'cogging':
        return [{'cogging_period_m': p} for p in (0.002, 0.0035, 0.006, 0.01, 0.015, 0.02)] + ripple_starts(
            rec, model, replay=pr)
    if name == 'delay':
        return [{'input_delay_s': d} for d in sorted({0.003, 0.01, 0.02, round(response_lag(rec), 4) or 0.001})]
    if name == 'deadzone':
        low = smallest_moving_command(rec) or 0.5
        return [{'deadzone_V': f * low} for f in (0.2, 0.5)]
    if name == 'saturation':
        umax = float(np.max(np.abs(rec.u)))
        return [{'saturation_V': f * umax} for f in (0.5, 0.8)]
    if name == 'backlash':
        return [{'backlash_m': g} for g in (3e-4, 1e-3, 3e-3)]
    if name == 'drive_backlash':
        return drive_starts(pr, model, model)
    if name == 'sensor_bias':
        return [{'bias_theta_rad': rest_offset(rec.theta) if rec.theta is not None else 0.0}]
    if name == 'lag':
        return [{'input_lag_s': tau} for tau in (0.003, 0.01, 0.03)]
    return [{}]


#: the cogging periods [m] :func:`ripple_starts` looks for (RIPPLE_PERIODS of them at least over the travel)
RIPPLE_RANGE = (0.0015, 0.03)
#: its periodogram's frequencies per peak width (a peak is 1 / travel wide in 1/m: a period 2.6 % off over
#: 20 periods of travel drifts by half a period; from a fixed grid's points 5 % apart a 7.74 mm cogging
#: was fitted at 8.41 mm)
RIPPLE_OVERSAMPLE = 4


def ripple_starts(rec: Record, model: Model, keep: int = 2, replay: Problem | None = None) -> list[dict]:
    """Cogging starts from the cart's force balance (:mod:`~ipfric_core.ident.equation_error`) of
    ``model``: its residual's periodogram over the position (Lomb-Scargle, periods of RIPPLE_RANGE, at
    RIPPLE_OVERSAMPLE frequencies per peak width), the ``keep`` peaks (15 % apart at least) that explain
    most of it, each with its amplitudes from the residual regressed on sin and cos(2 pi x / P) (the
    sign that lowers the balance's residual: the residual is minus the force the model lacks). From
    amplitudes of 0 the period has no gradient, and a fit from the nearest fixed period may stay at a
    small ripple of the wrong phase. With ``replay``, each start then where the replay of its cart's windows
    prefers it (:func:`phased`). Empty where the balance cannot be formed."""
    from .equation_error import Prepared, balance, parts
    try:
        pr = Prepared(rec)
        p = {q.name: q.value for q in model.params}
        active = parts(model.law, tuple(e for e in model.effects if e != 'cogging'))
        b = balance(pr, p, active)
    except (ConfigError, KeyError, ValueError):
        return []
    r, x = b.r[b.used], b.x[b.used]
    if len(r) < 50 or not np.any(r):
        return []

    travel = float(np.ptp(x))
    lo, hi = 2 * np.pi * max(1 / RIPPLE_RANGE[1], RIPPLE_PERIODS / max(travel, 1e-12)), 2 * np.pi / RIPPLE_RANGE[0]
    if lo >= hi:
        return []
    omega = np.arange(lo, hi, 2 * np.pi / (RIPPLE_OVERSAMPLE * travel))
    power = lombscargle(x, r, omega)
    peaks = [i for i in range(len(power)) if power[i] >= power[max(0, i - 1):i + 2].max()]

    def explained(period: float) -> tuple[float, float, np.ndarray]:
        basis = np.column_stack([np.sin(2 * np.pi * x / period), np.cos(2 * np.pi * x / period)])
        c, *_ = np.linalg.lstsq(basis, r, rcond=None)
        return float(np.sum((basis @ c) ** 2)), period, c
    fits = [explained(2 * np.pi / omega[i]) for i in sorted(peaks, key=lambda i: -power[i])[:4 * keep]]
    out: list[dict] = []
    for _, period, c in sorted(fits, key=lambda f: -f[0]):
        if len(out) == keep:
            break
        if any(abs(period / o['cogging_period_m'] - 1) < 0.15 for o in out):
            continue
        signed = []
        for sign in (-1.0, 1.0):
            q = {'cogging_sin_N': sign * float(c[0]), 'cogging_cos_N': sign * float(c[1]), 'cogging_period_m': period}
            res = balance(pr, {**p, **q}, active + ('cogging',)).r
            signed.append((float(res @ res), q))
        out.append(min(signed, key=lambda t: t[0])[1])
    return out if replay is None else [phased(replay, model, q, travel) for q in out]


#: the phases [rad] and periods (steps of a quarter of the periodogram's spacing) :func:`phased` tries at
#: twice the balance's size, then the sizes (factors of the balance's) at the best of them
PHASE_TURNS = np.arange(8) * (np.pi / 4)
PERIOD_STEPS = (-2, -1, 0, 1, 2)
AMPLITUDE_FACTORS = (2.0, 1.0, 4.0)


def phased(pr: Problem, model: Model, q: dict, travel: float) -> dict:
    """The ripple start ``q`` of :func:`ripple_starts` (over ``travel`` [m]) at the period, phase and size that
    replay the cart's windows of ``pr`` best, one simulation each (42): the periods within half the
    periodogram's spacing of its own (PERIOD_STEPS) at each of PHASE_TURNS about its phase, at twice its
    size, then that one at AMPLITUDE_FACTORS of its size. The force balance finds the period to within a
    spacing, over a hundred periods of travel a drift of a quarter period, and its filtered derivatives lag
    the position and smooth the ripple away: on a 3.17 mm cogging of 0.010 N it gave 3.165 mm and 0.0036 N
    about 50 degrees off, and a fit from there ended in another minimum of the simulation error (2.5
    counts; from the truth 1.6)."""
    base = model.with_effect('cogging')
    size, phase = math.hypot(q['cogging_sin_N'], q['cogging_cos_N']), math.atan2(q['cogging_cos_N'], q['cogging_sin_N'])
    period = float(q['cogging_period_m'])
    step = period ** 2 / (4 * RIPPLE_OVERSAMPLE * max(travel, period))

    def scored(f: float, turn: float, p: float) -> tuple[float, dict]:
        t = {'cogging_period_m': p, 'cogging_sin_N': f * size * math.cos(turn),
             'cogging_cos_N': f * size * math.sin(turn)}
        return pr.cart_cost(base.with_values(t)), t
    first, *others = AMPLITUDE_FACTORS
    best = min((scored(first, phase + d, period + k * step) for k in PERIOD_STEPS for d in PHASE_TURNS),
               key=lambda c: c[0])
    turn = math.atan2(best[1]['cogging_cos_N'], best[1]['cogging_sin_N'])
    return min([best] + [scored(f, turn, best[1]['cogging_period_m']) for f in others], key=lambda c: c[0])[1]


#: the grid :func:`drive_starts` evaluates: plays [m], motor-side masses [share of M], contact
#: frequencies [Hz] (the contact's stiffness k = m_r (2 pi f)^2, m_r the reduced mass), and the
#: contact's damping ratio
DRIVE_GRID = ((3e-4, 1e-3, 3e-3), (0.1, 0.25, 0.5), (50.0, 100.0, 200.0), 0.15)


def drive_starts(pr: Problem, model: Model, friction: Model, keep: int = 2, masses=None, gaps=None) -> list[dict]:
    """Start values of a drive with play: the ``keep`` best points of :data:`DRIVE_GRID` by the
    cart's estimation error (its error has many local minima: each contact frequency rings differently)
    at the friction of model ``friction`` (its law's values, each start carrying them): the current
    model's (in round 1 the declared one: a refit without the play distorts it, the Coulomb level sinks
    where the cart coasts through the play), and in round 1 the refit's too, where the declared friction is
    far off (seed 2027's
    case 138, a 0.40 mm play with 0.23 kg on its motor side in a balancing loop, declared Coulomb level 0.65
    N against 2.0: at the declared friction the grid's best points had a motor side of 0.63 kg and their
    short fits left 930-1090 counts on validation; at the refit's, 0.125 kg and 124-171). ``masses``: the
    motor sides [kg] to try instead of the grid's shares of the cart's mass; ``gaps``: the plays [m]
    instead of the grid's."""
    grid_gaps, shares, freqs, _ = DRIVE_GRID
    gaps = gaps or grid_gaps
    law = {n: friction[n] for n in LAW_PARAMS[friction.law]}
    grid = []
    for mass in masses or [share * model['M'] for share in shares]:
        reduced = mass * model['M'] / (mass + model['M'])
        for f in freqs:
            k = reduced * (2 * math.pi * f) ** 2
            grid += [{'drive_backlash_m': g, 'drive_mass_kg': mass, 'drive_stiffness_N_per_m': k,
                      'drive_damping_Ns_per_m': contact_damping(k, mass, model['M']), **law} for g in gaps]
    costs = [pr.cart_cost(model.with_effect('drive_backlash', p).with_values(p)) for p in grid]
    return [grid[i] for i in np.argsort(costs)[:keep]]


def law_starts(declared: Model) -> dict:
    """Start values of every friction parameter a law switch may need: the declared model's, else the
    typical sizes."""
    return {n: declared.get(n, PARAMS[n].typical) for n in FRICTION_FITTED}


#: the Stribeck velocities a law's fit also starts from, relative to its start: from the paper's 0.105 m/s a
#: fit of a curve 0.023 m/s wide stopped at 0.15 m/s (the Coulomb level low, the viscous slope high) and
#: lost to the coulomb law, whose lack of a curve then looked like an effect
STRIBECK_FACTORS = (0.25, 4.0)


def stribeck_starts(model: Model) -> list[dict]:
    """Further starts of a law with a Stribeck curve: its Stribeck velocity times STRIBECK_FACTORS (within
    its range); none for a law without one."""
    if 'v_s' not in LAW_PARAMS[model.law]:
        return []
    p = model.param('v_s')
    return [{'v_s': min(max(f * p.value, p.lo), p.hi)} for f in STRIBECK_FACTORS]


#: presliding displacements [m] the bristle starts of the dynamic law are taken at (sigma0 = Fs / z)
BRISTLE_Z = (1e-4, 1e-5)


def peak_level(model: Model) -> float:
    """The highest level of the model's Stribeck curve [N]: the static level, or the Coulomb level where the
    curve rises with speed (Fs_excess < 0)."""
    return model['Fc'] + max(model['Fs_excess'], 0.0)


def bristle_starts(model: Model) -> list[dict]:
    """Start values of the dynamic law's bristles: a stiffness that holds the static level within each
    presliding displacement of BRISTLE_Z, damped critically on the cart's mass (sigma1 = 2 sqrt(sigma0 M))."""
    fs = peak_level(model)
    p = model.param('sigma0')
    out = []
    for z in BRISTLE_Z:
        s0 = min(max(fs / z, p.lo), 0.5 * p.hi)
        out.append({'sigma0': s0, 'sigma1': min(2 * math.sqrt(s0 * model['M']), PARAMS['sigma1'].hi)})
    return out


def balance_starts(rec: Record, model: Model) -> dict[str, dict]:
    """Start values from the cart's force balance (equation error on filtered derivatives:
    :func:`~ipfric_core.ident.equation_error.base_fit`) of the model's friction law: ``'refit'`` its
    friction with the model's mass held; ``'M'`` the mass and friction the balance fits with the mass
    free, ``'alpha'`` the same balance read with the mass as declared (paper eq. 2 divided by M / M_fit:
    alpha, the viscous term beta + eps and the friction levels over that ratio). A simulation fit from
    the declared friction can end far from these where the declared values are far off (a viscous slope
    of 3 N s/m declared where the cart has 0.2). Empty where the balance cannot be fitted (a record that
    hardly moves)."""
    from .equation_error import Prepared, base_fit
    law = LAW_PARAMS[model.law]
    if model.law not in ('exponential', 'coulomb', 'viscous'):
        return {}
    try:
        pr = Prepared(rec)
        held = base_fit(rec, model.law, model['M'], pr).params
        free = base_fit(rec, model.law, None, pr).params
    except (ConfigError, ValueError, np.linalg.LinAlgError):
        return {}
    out = {'refit': {n: held[n] for n in law}, 'M': {'M': free['M'], **{n: free[n] for n in law}}}
    k = free['M'] / model['M']
    if k > 0:
        scaled = {n: free[n] / k for n in law if n in ('Fc', 'Fs_excess')}
        if 'eps' in law:
            scaled['eps'] = max((model['beta'] + free['eps']) / k - model['beta'], 0.05 * PARAMS['eps'].typical)
        out['alpha'] = {'alpha': model['alpha'] / k, **{n: free[n] for n in law}, **scaled}
    return out


def contact_damping(stiffness: float, motor: float, cart: float) -> float:
    """The damping [N s/m] of a drive's contact of ``stiffness`` [N/m] between a motor side and a cart of
    those masses [kg] at the damping ratio of :data:`DRIVE_GRID` (on their reduced mass)."""
    reduced = motor * cart / (motor + cart)
    return 2 * DRIVE_GRID[3] * math.sqrt(stiffness * reduced)
