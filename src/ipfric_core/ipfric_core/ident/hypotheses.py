"""The hypotheses a round of the ladder tries against the current model (:class:`Hypothesis`): the
declared law refitted, each other friction law, each plant correction and each library effect; their
short fits, which of them are fitted in full (:func:`screen`), and their full fits.

Each round, every candidate first gets a short fit (its own parameters and the friction
levels, SCREEN_NFEV steps from each of its starts) on the cart's windows alone (the angle's
too for an effect on the angle), on every k-th window where the estimation record holds more
than SCREEN_SAMPLES samples per block (judged on every window: a short fit that does not carry
over is done again on all); only the candidates whose short fit lowers the estimation error
by at least FULL_SHARE of the best one's are fitted in full and judged (the others are
listed with that reason and tried again next round).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from .effects import EFFECTS
from .model import LADDER_EFFECTS, LAW_PARAMS, Model
from .problem import SCREEN_NFEV, Problem, fit_model
from .refutations import CLOSED_PLAY, bound_params, contradictions, play_closed, size_params, smallest_play, untold
from .starts import (
    bristle_starts,
    contact_damping,
    drive_starts,
    effect_starts,
    law_starts,
    peak_level,
    stribeck_starts,
)

__all__ = ['refit_of', 'LAWS', 'PLANT_CORRECTIONS', 'CORRECTABLE', 'Hypothesis', 'hypotheses', 'refinements',
           'free_levels', 'heavier_cart', 'in_place_of_mass', 'with_play_closed', 'with_play_opened', 'short_fit',
           'short_fits', 'joint', 'full_fit', 'beta_for_eps', 'contact_held', 'errors_of', 'screen']

#: the friction laws the ladder weighs against each other
LAWS = ('viscous', 'coulomb', 'exponential', 'dynamic')
#: the declared plant constants the ladder may correct (an effective mass with the rotor reflected, the motor's
#: force per volt); not the back-EMF beta: it acts on the cart as the viscous slope eps does, which every law fits
PLANT_CORRECTIONS = ('M', 'alpha')
#: the declared constants a final model may correct: the plant corrections, and beta where the data want less
#: viscous damping than it gives (:func:`beta_for_eps`)
CORRECTABLE = PLANT_CORRECTIONS + ('beta',)
SCREEN_GAIN = 0.01       # an effect whose own parameters lower the estimation cost less is not refitted
#: effects started from a grid of their error: when its best point lowers the cart's estimation cost by
#: less than SCREEN_GAIN, they are not fitted (a drive play's simulation costs tens of ordinary ones)
GRID_SCREENED = ('drive_backlash',)
FULL_SHARE = 0.5         # a candidate is fitted in full when its short fit gains this share of the best one's
FULL_TOP = 3             # and is among the best FULL_TOP of its group
REDO_GAIN = 0.1          # a short fit that gains this much on a subset of windows and nothing on all is redone on all
#: and one that leaves every window this much worse than the model it starts from (its friction levels
#: wandered off on the subset)
REDO_LOSS = 0.1


#: the lightest motor side of a drive with play the ladder fits [share of the cart's mass]
MIN_DRIVE_SHARE = 0.02
#: the least back-EMF a correction of beta may find [share of the declared beta] (:func:`beta_for_eps`)
MIN_BETA_SHARE = 0.5


@dataclass
class Hypothesis:
    """One explanation of what the current model misses: a model with some parameters to fit.

    kind : 'friction' (the declared law refitted), 'law' (another friction law), 'plant' (a declared
        constant corrected: the effective mass with the rotor reflected, the motor's alpha or beta) or
        'effect' (one of the library's, with the friction levels refitted beside it or, on the declared
        friction, alone)
    own : the parameters that are the hypothesis (checked: bounds, size, relevance)
    free : the parameters its short fit moves (own, and the friction levels where they may move)
    """

    label: str
    kind: str
    model: Model
    own: tuple
    free: tuple
    starts: list = field(default_factory=lambda: [{}])
    effect: str | None = None
    #: an effect of GRID_SCREENED: not fitted when the best of its starts explains nothing (False where its
    #: starts already explain what the current model does: a drive in place of a mass correction)
    screened: bool = True
    #: a drive's grid (:func:`drive_starts`' ``masses`` and ``gaps``), ranked again at the refit's friction
    #: where its short fit starts from it (:func:`short_fits`); None for other hypotheses
    grid: dict | None = None

    @property
    def levels(self) -> set:
        """The parameters its fit moves beside its own: the friction levels refitted with it."""
        return set(self.free) - set(self.own)

    def refines(self, current: Model) -> bool:
        """Whether it refines an effect ``current`` already holds (:func:`refinements`: a kept drive's play
        opened) rather than adding one."""
        return self.effect is not None and self.effect in current.effects


def refit_of(current: Model, starts: list | None = None) -> Hypothesis:
    """The hypothesis that ``current``'s friction levels (its law's) are off: they are refitted."""
    law = current.law_fitted()
    return Hypothesis('refit', 'friction', current.with_free(law), law, law, starts or [{}])


def hypotheses(pe: Problem, current: Model, declared: Model, allowed=None, balance: dict | None = None
               ) -> list[Hypothesis]:
    """The explanations a round tries against ``current`` (see :class:`Hypothesis`): the declared law
    refitted (until it is), each other law, each plant correction not made yet, each library effect not
    added (``allowed`` restricts them), with the friction levels refitted and, before any refit, also
    on the declared friction alone. ``balance``: further starts of the refit and the plant corrections
    (:func:`balance_starts`). A law refitted with some of its levels held (:func:`full_fit`) counts as
    refitted, and the held ones stay held: the data did not determine them."""
    rec = pe.rec
    law = current.law_fitted()
    refitted = any(current.param(n).free for n in law)
    levels = free_levels(current)
    balance = balance or {}
    heavier = heavier_cart(current, declared, rec.theta is None)
    out = []
    if not refitted:
        out.append(refit_of(current, [{}] + stribeck_starts(current)
                            + ([balance['refit']] if 'refit' in balance else [])))
    for other in LAWS:
        if other != current.law:
            m = current.with_law(other, law_starts(declared))
            if other == 'dynamic':      # bristles stiffer than a tenth of a count of presliding are not seen
                m = m.with_bounds('sigma0', 0.0, 10 * peak_level(m) / rec.x_resolution)
            out.append(Hypothesis(f'law {other}', 'law', m, m.law_fitted(), m.law_fitted(),
                                  bristle_starts(m) if other == 'dynamic' else [{}] + stribeck_starts(m)))
    for name in PLANT_CORRECTIONS:
        if not current.param(name).free:
            out.append(Hypothesis(f'{name} corrected', 'plant', current.with_free((name,) + law), (name,),
                                  (name,) + law, [{}] + ([balance[name]] if name in balance else [])))
    out += refinements(pe, current)
    for name in LADDER_EFFECTS:
        if name in current.effects or (allowed is not None and name not in allowed):
            continue
        if EFFECTS[name].needs_theta and rec.theta is None:
            continue
        own = EFFECTS[name].params
        starts = effect_starts(pe, current, name)
        base = current.with_effect(name)
        if name == 'drive_backlash':   # a motor side lighter than this is no drive (and its contact rings at kHz)
            base = base.with_bounds('drive_mass_kg', MIN_DRIVE_SHARE * current['M'], math.inf)
        out.append(Hypothesis(name, 'effect', base.with_free(levels), own, own + levels, starts, name,
                              grid={} if name == 'drive_backlash' else None))
        if name == 'drive_backlash':
            out.append(with_play_closed(pe, out[-1], current))
            if heavier is not None:
                out.append(in_place_of_mass(pe, heavier, declared, 'M' if current.param('M').free else 'alpha'))
                out.append(with_play_closed(pe, out[-1], heavier, [heavier['M'] - declared['M']]))
        if not refitted:
            out.append(Hypothesis(f'{name} on the declared friction', 'effect', base, own, own, starts, name))
    return out


def free_levels(current: Model) -> tuple:
    """The friction levels (Fc, Fs_excess of ``current``'s law) an effect is fitted with: the refitted ones,
    all of them before a refit."""
    law = current.law_fitted()
    refitted = any(current.param(n).free for n in law)
    return tuple(n for n in ('Fc', 'Fs_excess') if n in law and (current.param(n).free or not refitted))


def refinements(pe: Problem, current: Model) -> list[Hypothesis]:
    """The hypotheses that refine an effect ``current`` already holds: its compliant drive's play opened where
    it is held closed (:func:`with_play_opened`). A round tries them even where ``current`` explains the data
    to the encoders' floor: that floor is the replay of a cart without play (its motor side moving with it:
    :func:`~ipfric_core.ident.judging.rounding_model`), whose start speeds are estimated from the readings,
    while a drive's motor side starts at the smoothed speed; seed 2027's case 34 (a 0.026 mm play, a hanging
    pendulum) left 5.77 counts on validation with the play closed, within 1.5 times its floor of 4.19, and
    0.98 with the true play."""
    return [with_play_opened(pe, current, free_levels(current))] if play_closed(current) else []


#: the plays [m] of a drive in place of a mass correction, each a start (seed 2027's case 69, a 2.33 mm play:
#: from 1 mm the fit ended at 1.24 mm, 4.74 counts on estimation, from 3 mm at 2.72 mm and 2.15), beside the
#: smallest play the ladder keeps, two encoder counts (:func:`in_place_of_mass`)
IN_PLACE_GAPS = (1e-4, 3e-4, 1e-3, 3e-3)


def heavier_cart(current: Model, declared: Model, cart_alone: bool) -> Model | None:
    """``current`` as a cart heavier than declared: itself where it corrects M upwards; on the cart alone,
    where it corrects alpha downwards, the same motion with alpha as declared and the mass, every force
    and the viscous term divided by alpha's share of the declared value (paper eq. 2, M x'' = alpha V -
    (beta + eps) x' - F: on the cart alone the data fix M / alpha only); else None."""
    if current.param('M').free:
        return current if current['M'] > declared['M'] else None
    if not (cart_alone and current.param('alpha').free and current['alpha'] < declared['alpha']):
        return None
    ratio = declared['alpha'] / current['alpha']
    scaled = {p.name: p.value * ratio for p in current.params
              if p.unit.startswith('N') and p.name not in ('alpha', 'beta', 'eps')}
    if current.viscous_in_beta:
        scaled['beta'] = current['beta'] * ratio
    else:
        scaled['eps'] = (current['beta'] + current['eps']) * ratio - current['beta']
    return current.holding({'alpha': declared['alpha']}).with_values({**scaled, 'M': current['M'] * ratio}) \
        .with_free(('M',))


def in_place_of_mass(pe: Problem, current: Model, declared: Model, corrected: str = 'M') -> Hypothesis:
    """A drive with play in place of a mass correction: the cart's mass as declared again, the mass the
    correction added on the drive's motor side (a rotor and gears reflected to the rack move with the
    cart while the play is closed: a heavier cart, until the drive reverses), the friction as fitted
    with the correction. It starts from each play of IN_PLACE_GAPS (the best contact of
    :func:`drive_starts` with that motor side for each: ranked at the friction the correction bent, the
    true play's neighbourhood ranks last) and fits the whole law beside its own parameters (seed 2027's
    case 77, a 1.87 mm play: the correction's fit had the viscous slope 5 % and the Stribeck velocity
    16 % off, and with them held a short fit from 1 mm ended behind one from 0.3 mm, 18.9 counts against
    17.5; with them free, 5.3 against 12.0, and the law within 0.5 % of the truth). A play of two encoder
    counts, the smallest the ladder keeps (:func:`refutations.smallest_play`), is a start too where it is
    below IN_PLACE_GAPS' first (seed 2027's case 74, a 0.039 mm play, 2.3 counts of 0.017 mm: from 0.1 mm
    the fit ended at 0.12 mm with 3.47 counts on validation and from 0.3 mm at 0.30 mm with 8.88, the
    mass correction left 6.85; from 0.034 mm, at 0.045 mm with 2.82). ``current`` is the heavier cart of the
    model whose correction ``corrected`` the drive takes the place of: an alpha correction on the cart alone
    too, from the same motion as a heavier cart (:func:`heavier_cart`; seed 2027's case 191,
    a 0.046 mm play, 4.1 counts, with 0.457 kg on the motor side: alpha corrected left 7.81 counts on
    validation, the drive in place of it reaches 0.024 mm with 0.457 kg and leaves 2.46)."""
    name = 'drive_backlash'
    base = current.holding({'M': declared['M']}).with_effect(name)
    base = base.with_bounds('drive_mass_kg', MIN_DRIVE_SHARE * declared['M'], math.inf)
    extra = current['M'] - declared['M']
    smallest = smallest_play(pe.rec)
    gaps = ((smallest,) if smallest < IN_PLACE_GAPS[0] else ()) + IN_PLACE_GAPS
    starts = [s for gap in gaps for s in drive_starts(pe, base, current, keep=1, masses=[extra], gaps=[gap])]
    own, law = EFFECTS[name].params, current.law_fitted()
    return Hypothesis(f'{name} in place of {corrected} corrected', 'effect', base.with_free(law), own, own + law,
                      starts, name, screened=False)


def with_play_closed(pe: Problem, h: Hypothesis, friction: Model, masses: list | None = None) -> Hypothesis:
    """The drive of ``h`` with its play held closed (CLOSED_PLAY): a compliant contact without play, a
    motor side that moves with the cart through a spring and a damper (a belt, a rack's teeth under
    preload). A play below two encoder counts is refuted (the readings' rounding), and a rigid contact is a
    heavier cart; between the two, a motor side behind a play the encoder cannot show rings against the cart
    (seed 2027's cases 71 and 106, plays of 0.5 and 0.25 counts: a mass correction left 25 and 13 counts on
    validation, the drive with its play closed 1.8 and 0.6). Started from the best contacts of
    :func:`drive_starts` at the closed play and the friction of ``friction`` (``masses``: the motor
    sides [kg] to try, as ``h``'s); its label says it."""
    name = 'drive_backlash_m'
    model = h.model.holding({name: CLOSED_PLAY})
    grid: dict = {'masses': masses, 'gaps': [CLOSED_PLAY]}
    starts = drive_starts(pe, model, friction, **grid)
    label = h.label.replace('drive_backlash', 'drive_backlash with its play closed', 1)
    return Hypothesis(label, h.kind, model, tuple(n for n in h.own if n != name), tuple(n for n in h.free if n != name),
                      starts, h.effect, screened=h.screened, grid=grid)


#: the plays [encoder counts] :func:`with_play_opened` starts from beside IN_PLACE_GAPS
OPENED_COUNTS = (2.0, 4.0, 8.0)


def with_play_opened(pe: Problem, current: Model, levels: tuple) -> Hypothesis:
    """The compliant drive of ``current`` (its play held closed: :func:`with_play_closed`, kept by an earlier
    round) with its play fitted, the contact, the motor side and the friction levels ``levels`` with it:
    started from the smallest play the ladder keeps at ``current``'s contact, and from the two best points
    of :func:`drive_starts`' contacts at ``current``'s motor side with plays of OPENED_COUNTS encoder counts
    and IN_PLACE_GAPS above them. A round that kept the closed drive found the motor side where a play's
    start had none (seed 2027's case 191 on the cart alone, a 0.046 mm play, 4.1 counts: the closed drive
    kept in round 1, with a contact of 4.6e4 N/m against the truth's 4.6e5, left 5.07 counts on validation,
    and with the drive in the model no round tried its play; opened from its own contact, the fit stayed
    there, 4.53 counts and not significant; from the grid's best contact, 5.4e5 N/m, it reached 0.038 mm
    and 2.32 counts). Judged as a drive with play is (its play against the closed one:
    :func:`~ipfric_core.ident.ladder.play_checks`); what it adds is its play."""
    name = 'drive_backlash'
    counts = [c * pe.rec.x_resolution for c in OPENED_COUNTS]
    plays = counts + [g for g in IN_PLACE_GAPS if g > counts[-1]]
    model = current.with_free(('drive_backlash_m',) + levels)
    starts = [{'drive_backlash_m': plays[0]}] + drive_starts(pe, model, current, masses=[current['drive_mass_kg']],
                                                             gaps=plays)
    own = EFFECTS[name].params
    return Hypothesis(f'{name} with its play opened', 'effect', model, own, own + levels, starts, name, screened=False)


def short_fit(pe: Problem, current: Model, h: Hypothesis, prior: Model, ps: Problem) -> tuple[Model, float]:
    """The best short fit of hypothesis ``h`` over its starts (SCREEN_NFEV steps each, its ``free``
    parameters) on the cart's windows of ``ps`` (:meth:`Problem.screen`; the angle's too for an effect on
    the angle), and the share by which it lowers the estimation error of every window of ``pe`` (0 for a
    drive play whose best grid point explains nothing: not fitted). Where the subset's fit does not
    carry over to every window (it gains REDO_GAIN on the subset, less than SCREEN_GAIN on all, or it
    leaves all REDO_LOSS worse than ``current``: its friction levels wandered off on the subset), the
    fits are done again on ``pe``; on the subset, the gain is counted from the friction levels refitted
    there alone (:meth:`Problem.baseline`), not from ``current``. The best start the data do not contradict
    (:func:`contradictions`) is taken over a better one they do: a real cart's cogging fitted at 20 mm from
    one start, fewer than two periods over its 30.6 mm of travel, at a shorter period from another."""
    starts = [h.model.with_values(s) for s in h.starts]
    if h.effect in GRID_SCREENED and h.screened:
        costs = [ps.cart_cost(m) for m in starts]
        if min(costs) > (1 - SCREEN_GAIN) * ps.cart_cost(current):
            return starts[int(np.argmin(costs))], 0.0   # the best of a grid explains nothing: not fitted
    levels = h.levels
    on_angle = h.effect is not None and EFFECTS[h.effect].needs_theta

    def fit(pr):
        pr = pr if on_angle else pr.cart()
        fits = [fit_model(pr, m, max_nfev=SCREEN_NFEV, only=set(h.free), prior=prior, errors=False)[0]
                for m in starts]
        ranked = [fits[i] for i in np.argsort([pr.cost(m) for m in fits])]
        best = next((m for m in ranked if not (h.effect and contradictions(pe, m, h.effect))), ranked[0])
        return best, 1.0 - pr.cost(best) / pr.cost(pr.baseline(current, levels, prior))
    best, gain = fit(ps)
    full = 1.0 - pe.cost(best) / pe.cost(current)
    if ps is not pe and full < SCREEN_GAIN and (gain >= REDO_GAIN or full < -REDO_LOSS):
        best, _ = fit(pe)
        full = 1.0 - pe.cost(best) / pe.cost(current)
    return best, full


def short_fits(pe: Problem, current: Model, hs: list[Hypothesis], prior: Model, ps: Problem
               ) -> list[tuple[Model, float]]:
    """:func:`short_fit` of every hypothesis of a round, the refit's first: each effect that refits the
    friction levels beside its own parameters then starts from the whole law as the refit's short fit
    left it, and fits the law with its own parameters in full. From the declared friction, a short fit of
    the levels alone could not reach what the refit reaches by the viscous slope and the Stribeck
    velocity too, and every such effect lost to the refit, or to a plant correction that took the refit
    with it (a delay of a sixth of a sample answered by alpha 0.8 % low). Such an effect also starts
    from its own short fit on the declared friction, the whole law free from there: a refit without the
    effect may have bent the law to make up for it (an amplifier clipping at 4.5 V: the refit sank the
    Coulomb level to 0, the clipping fitted from there ended with the viscous slope on its bound 0, while
    from the clipping fitted on the declared friction the law reached the truth and 0.45 counts). A plant
    correction, which refits the whole law itself, starts from both: a refit without it may have bent the
    friction to make up for a wrong mass (a motor side that moves with the cart: the viscous slope sank to
    0). A drive's starts carry their friction (:func:`drive_starts`): its grid is also ranked at the refit's
    (on the screen's windows), and those points start from it."""
    out: dict[int, tuple[Model, float]] = {i: short_fit(pe, current, h, prior, ps)
                                           for i, h in enumerate(hs) if h.kind == 'friction'}
    seed = {}
    if out:
        refit = next(iter(out.values()))[0]
        law = refit.law_fitted()
        seed = {n: refit[n] for n in law}
    with_levels = [i for i, h in enumerate(hs) if h.kind == 'effect' and h.levels]
    for i, h in enumerate(hs):
        if i in out or i in with_levels:
            continue
        if seed and h.kind == 'plant':
            h = replace(h, starts=h.starts + [seed])
        hs[i] = h
        out[i] = short_fit(pe, current, h, prior, ps)
    on_declared = {h.effect: out[i][0] for i, h in enumerate(hs)
                   if h.kind == 'effect' and i not in with_levels}
    for i in with_levels:
        h = hs[i]
        if seed:
            own = on_declared.get(h.effect)
            grid = drive_starts(ps, h.model, refit, **h.grid) if h.grid is not None else []
            h = replace(h, model=h.model.with_free(law), starts=[{**seed, **st} for st in h.starts + grid]
                        + ([{n: own[n] for n in h.own}] if own is not None else []))
        hs[i] = h
        out[i] = short_fit(pe, current, h, prior, ps)
    return [out[i] for i in range(len(hs))]


def joint(h: Hypothesis, model: Model) -> set:
    """The parameters a hypothesis's full fit moves: its own and those the model already fits (its
    friction law's among them)."""
    return set(h.free) | {p.name for p in model.free}


def full_fit(pe: Problem, h: Hypothesis, best: Model, prior: Model) -> Model:
    """The fit of the hypothesis's parameters with every parameter the model already fits (:func:`joint`),
    from its short fit ``best``. A refit of the declared law that puts one of its levels on a bound is done
    again with that level held at its declared value, and any hypothesis that fits the Coulomb level and
    ends with it within two standard errors of zero (:func:`untold`) with it held at its value in the
    hypothesis's start model (the declared one, or the one an earlier round fitted): the data did not
    determine it (below the Stribeck velocity the Coulomb level and the curve's width trade; a balancing
    loop's cart seldom stops), and neither a bound nor a cart without Coulomb friction is an answer (an
    amplifier clipping at 2.7 V that explained a balancing loop to its floor was refused for an Fc of
    0.07 +/- 0.13 N). That test checks the Coulomb level's error alone (:func:`errors_of` ``among``): the
    others are computed for the hypotheses that pass (:func:`~ipfric_core.ident.ladder.confirm`). A fit that
    puts the viscous slope on 0 is done again with the viscous term in beta (:func:`beta_for_eps`)."""
    def fit(m: Model, held: dict) -> Model:
        m = fit_model(pe, m.holding(held), only=joint(h, m) - set(held), prior=prior, errors=False)[0]
        return beta_for_eps(pe, h, m, prior)
    m = fit(best, {})
    contact = contact_held(m)
    if contact:
        m = fit(m, contact)
    fits_fc = 'Fc' in {p.name for p in m.free}
    if h.kind != 'friction' and not fits_fc:
        return m
    held: dict = dict(contact)
    for _ in LAW_PARAMS[m.law]:      # a level held, another may go to its bound: until none does
        new = {p.name: prior[p.name] for p in bound_params(m)
               if h.kind == 'friction' and p.name in LAW_PARAMS[m.law]}
        if not new and fits_fc and 'Fc' not in held:
            if untold(m, errors_of(pe, h, m, prior, among={'Fc'})):
                new = {'Fc': h.model['Fc']}
        if not new:
            break
        held.update(new)
        m = fit(m, held)
    return m


def beta_for_eps(pe: Problem, h: Hypothesis, m: Model, prior: Model) -> Model:
    """``m`` fitted again with the viscous slope eps held at 0 and the back-EMF beta fitted, where the fit
    put eps on its lower bound 0: the data want less viscous damping than the declared beta gives (F =
    alpha V - (beta + eps) x', paper eq. 2), which eps >= 0 cannot take and beta can (a motor's winding
    resistance or torque constant off moves alpha and beta together). Else ``m``. Seed 2027's case 67, a
    balancing loop whose declared beta is 13 % high and whose motor side moves with the cart: the mass
    correction ended with eps on 0 (10.2 counts on validation); with beta fitted, 11.1 N s/m against the
    true beta + eps of 11.8 and 7.4 counts. Not where beta falls to MIN_BETA_SHARE of the declared value:
    a motor driven by voltage brakes by its back-EMF, and a fit that takes that away makes up for something
    else (seed 2027's case 25, a cart whose amplifier clips: the refit sank beta to 0 and, refused for it,
    left the clipping nothing to be judged against). Nor where no back-EMF is declared (a force input, a
    current-driven motor: beta 0)."""
    p = next((q for q in bound_params(m) if q.name == 'eps'), None)
    if p is None or prior['beta'] <= 0.0 or p.value - p.lo > p.hi - p.value:
        return m
    moved = m.holding({'eps': 0.0}).with_free(('beta',)).with_bounds('beta', MIN_BETA_SHARE * prior['beta'], math.inf)
    fitted = fit_model(pe, moved, only=joint(h, m) | {'beta'}, prior=prior, errors=False)[0]
    return m if fitted.param('beta') in bound_params(fitted) else fitted


def contact_held(model: Model) -> dict:
    """The damping of a drive's contact where a fit put it on a bound, at the damping ratio of
    :data:`DRIVE_GRID` for the fitted stiffness and masses: a stiff contact rings for a few milliseconds
    at each knock, too briefly for the encoder to tell its damping (the play, the motor side and the
    friction, which the data do fix, are fitted again with it held there)."""
    p = model.param('drive_damping_Ns_per_m') if 'drive_backlash' in model.effects else None
    if p is None or not p.free or p not in bound_params(model):
        return {}
    return {p.name: contact_damping(model['drive_stiffness_N_per_m'], model['drive_mass_kg'], model['M'])}


def errors_of(pe: Problem, h: Hypothesis, model: Model, prior: Model, among=None) -> dict:
    """The standard errors of a fitted hypothesis's parameters at its fit (no step taken: the Jacobian
    there, checked along each parameter of its own, or of those of them in ``among``; :func:`fit_model`)."""
    profile = set(size_params(model, h.effect or '')) | set(h.own)
    return fit_model(pe, model, max_nfev=0, only=joint(h, model), prior=prior,
                     profile=profile if among is None else profile & set(among))[1]


def screen(hs: list[Hypothesis], short: list[tuple[Model, float]], pe: Problem, current: Model
           ) -> list[str | None]:
    """Which hypotheses are fitted in full this round: per hypothesis None, or why not. An effect or a plant correction
    with the friction levels free is measured by what it adds to the refit's short fit (the refit's gain it takes
    for free; :func:`beyond_refit` judges them so); the others by their gain over ``current``. A short fit the data
    already contradict (:func:`contradictions`) is refused here and takes no place in its group, except a kept
    effect's refinement, whose full fit the same checks judge (a drive's opened play: docs/identification.md,
    seed 2027's case 138). A hypothesis is
    fitted in full when its gain reaches SCREEN_GAIN and FULL_SHARE of the best of its group's, and it is among the
    FULL_TOP best of it. The plant corrections (two at most) take no place in the ranks and do not set the bar: each
    is fitted in full when its gain beyond the refit reaches FULL_SHARE of the best effect's. Measured over
    ``current``, a mass and a motor factor each took a full fit on a 2-minute balancing loop whose cogging alone
    explained it (a quarter of the identification's time); ranked among the effects, a real cart's motor factor lost
    its full fit to three effects, and a mass correction's bar kept a real cart's amplifier clipping from its full
    fit. Fitted in full whenever they reach SCREEN_GAIN, outside the ranks: the refit of the declared law (the
    hypotheses that carry it must beat it: :func:`beyond_refit`; screened out by rank, it left a balancing loop with
    nothing kept where it alone explained 37 % of the validation error), and the leaner laws where the refit's short
    fit ends on a bound (the declared law is refuted there, and a law with more parts ends on the same bound: a cart
    logged at 30 ms whose refit lost its Coulomb level kept nothing, the viscous law ranked fourth), and a kept
    effect's refinement (:func:`refinements`: one per kept effect, nested in the current model, not one of the
    library's; seed 2027's case 74, a 0.04 mm drive play held closed, 2.75 counts on validation: opened, 1.50, but
    its short fit gained 2.8 % beyond the refit's against the best effect's 15 %: not fitted)."""
    refit = next((m for h, (m, _) in zip(hs, short) if h.kind == 'friction'), None)
    base = pe.cost(refit) if refit is not None else None
    refuted_law = refit is not None and any(p.name in LAW_PARAMS[refit.law] for p in bound_params(refit))
    gains = []
    refuted = []
    forced = []
    for h, (m, g) in zip(hs, short):
        levels = bool(h.levels) and h.kind in ('effect', 'plant')
        gains.append((levels, 1.0 - pe.cost(m) / base if levels and base else g))
        why = contradictions(pe, m, h.effect) if h.effect and g >= SCREEN_GAIN and not h.refines(current) else []
        refuted.append('its short fit: ' + '; '.join(why) if why else None)
        leaner = h.kind == 'law' and len(h.own) < len(LAW_PARAMS[current.law])
        forced.append(g >= SCREEN_GAIN and (h.kind == 'friction' or h.refines(current) or (leaner and refuted_law)))
    plant = [h.kind == 'plant' for h in hs]
    alive = [(lv, g) for (lv, g), r, f, pl in zip(gains, refuted, forced, plant) if r is None and not f and not pl]
    top = {grp: max([g for lv, g in alive if lv == grp], default=0.0) for grp in (True, False)}
    rank = {grp: sorted((g for lv, g in alive if lv == grp), reverse=True) for grp in (True, False)}
    out: list[str | None] = []
    for (lv, g), r, f, pl in zip(gains, refuted, forced, plant):
        what = 'beyond the refit\'s' if lv else 'over the model\'s'
        if r is not None:
            out.append(r)
        elif f:
            out.append(None)
        elif g < SCREEN_GAIN:
            out.append(f'its short fit lowers the estimation error by {100 * g:.2g} % {what} only')
        elif g < FULL_SHARE * top[lv]:
            best = 'effect' if pl else 'one'
            out.append(f'its short fit lowers the estimation error by {100 * g:.2g} % {what}, less than '
                       f'{100 * FULL_SHARE:g} % of the best {best}\'s {100 * top[lv]:.2g} %: not fitted in full '
                       f'this round')
        elif not pl and rank[lv].index(g) >= FULL_TOP:
            out.append(f'its short fit lowers the estimation error by {100 * g:.2g} % {what}: not among the '
                       f'{FULL_TOP} best of its group, not fitted in full this round')
        else:
            out.append(None)
    return out
