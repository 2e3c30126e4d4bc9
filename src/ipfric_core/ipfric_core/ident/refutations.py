"""What refutes a fitted model besides its simulation error: what the record itself shows (its
breakaways from rest, steady speeds, the lag of its response, a drive's crossings of its play, its rest
angle) and contradicts, a parameter that ends on a bound of its range, and a size, a Coulomb level or a
plant correction not told from zero or from the value it corrects, a static friction that no command of
the record could overcome."""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import linprog

from ..analysis.records import Record, smooth_rate
from ..physics.friction import holding_margin, static_limit, sticks
from ..physics.plant import undeclared_force
from ..physics.rig import drive_means, input_effects
from . import shooting
from .effects import PARAMS, static_level
from .model import Model
from .problem import Problem

__all__ = ['SIZE', 'RIPPLE_PERIODS', 'valid_moves', 'stops', 'stops_and_starts', 'smallest_moving_command',
           'steady_speeds', 'response_lag', 'crossings', 'unseen', 'drive_crossings', 'widest_play',
           'contradictions', 'unresolved', 'near', 'uncorrected', 'rest_offset', 'no_static_level', 'bound_params',
           'on_bounds', 'untold', 'reversals', 'never_starts', 'unheld_travels', 'never_holds', 'unfit',
           'smallest_play', 'CLOSED_PLAY', 'play_closed', 'size_params']

PLAY_COUNTS = 2.0        # a play (the encoder's or a drive's) below this many encoder counts is quantization
CLOSED_PLAY = 1e-9       # a drive's play closed [m]: a compliant contact without play (0 takes the drive away)
UNDO_SIGMA = 2.0         # a correction that ends this many standard errors from the declared value or closer is undone
STOP_S = 0.05            # a stretch this long with the encoder still is a stop [s]
BREAKAWAY_S = 0.5        # a cart that starts from rest travels three counts within this long [s]
HOLD_COUNTS = 3.0        # a stop a law without static friction leaves by this many encoder counts refutes it
#: a cogging repeats at least this often over the travel: once repeated, a force is a ripple (a balancing loop's
#: cart travels 31 mm: a 14 mm cogging of 2.5 counts, fitted at 13.6 mm, was refused at three)
RIPPLE_PERIODS = 2.0
#: the least share of the commands a saturation clips: an amplifier limit the commands reach 0.37 % of the time
#: moved a cart by 15 counts RMS (seed 2027, case 50, refused at 1 %); below it, a handful of peaks
MIN_CLIPPED = 0.001
#: the span [s] over which the readings' fastest speed is taken (:func:`widest_play`)
SPEED_SPAN_S = 0.02


def valid_moves(rec: Record) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The valid readings (the stale ones after a sample overrun repeat the reading before): their sample
    indices, positions [m], stamps [s], and the positions among them after which the reading changes."""
    keep = np.flatnonzero(rec.valid_mask)
    x, t = rec.x[keep], rec.t[keep]
    return keep, x, t, np.flatnonzero(np.diff(x) != 0.0)


def stops(rec: Record) -> list[tuple[int, int]]:
    """(first, last) sample of every stop: a stretch of STOP_S or longer between two moves of the cart
    over which the encoder stands still, read on the valid readings (:func:`valid_moves`: a cart frozen by
    overruns for 60 ms of a 10 ms loop has not stopped)."""
    keep, x, t, moves = valid_moves(rec)
    return [(int(keep[a + 1]), int(keep[b])) for a, b in zip(moves[:-1], moves[1:]) if t[b] - t[a + 1] >= STOP_S]


def stops_and_starts(rec: Record) -> list[tuple[int, int]]:
    """(last still sample, first moving sample) of every breakaway after a stop (:func:`stops`)."""
    keep = np.flatnonzero(rec.valid_mask)
    return [(last, int(keep[np.searchsorted(keep, last) + 1])) for _, last in stops(rec)]


def smallest_moving_command(rec: Record) -> float | None:
    """The command that moved the cart from rest [V]: the largest |command| over the 5 ms before
    each breakaway, its 10th percentile over the breakaways. A deadzone must be below it (a
    larger one would have kept the cart still). None with a pendulum attached: its swing moves the
    cart with no command at all."""
    if rec.theta is not None:
        return None
    vals = []
    for still, _ in stops_and_starts(rec):
        lo = np.searchsorted(rec.t, rec.t[still] - 0.005)
        vals.append(float(np.max(np.abs(rec.u[lo:still + 1]))))
    return float(np.quantile(vals, 0.1)) if len(vals) >= 3 else None


def steady_speeds(rec: Record, hold_s: float = 0.3) -> list[tuple[float, float]]:
    """(|command| [V], |speed| [m/s]) at the end of every stretch the command stayed constant
    for ``hold_s``: a saturation at u_max is refuted by speeds still growing above it."""
    u, t = rec.u, rec.t
    change = np.flatnonzero(np.diff(u) != 0.0)
    bounds = np.concatenate([[0], change + 1, [len(u)]])
    out = []
    for a, b in zip(bounds[:-1], bounds[1:]):
        if t[b - 1] - t[a] >= hold_s and u[a] != 0.0:
            k = np.searchsorted(t, t[b - 1] - 0.1)
            if b - 1 > k:
                out.append((abs(float(u[a])), abs(float((rec.x[b - 1] - rec.x[k]) / (t[b - 1] - t[k])))))
    return out


def response_lag(rec: Record, max_lag: float = 0.1) -> float:
    """Lag [s] at which changes of the cart's acceleration follow changes of the command best (a
    step of the force is a step of the acceleration): a transport delay longer than it (plus
    two samples) is not in the data."""
    v = smooth_rate(rec.t, rec.x, rec.valid_mask, shooting.FILTER_HZ)
    du, da = np.diff(rec.u), np.diff(np.gradient(v, rec.t))
    n = int(max_lag / rec.dt)
    cc = [float(np.dot(du[:len(du) - k], da[k:])) for k in range(n)]
    return int(np.argmax(cc)) * rec.dt


def crossings(side: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The crossings of a drive's whole play in the contact sides ``side`` of each sample (+1 / -1 in
    contact pushing forward / backward, 0 in the play): the last sample in contact before each and the
    first one after, on the other side (a reversal of the drive force)."""
    touch = np.flatnonzero(side != 0.0)
    before, after = touch[:-1], touch[1:]
    across = side[before] != side[after]
    return before[across], after[across]


def unseen(samples: np.ndarray) -> bool:
    """A play crossed between two readings, at the median of its crossings' ``samples`` (each from the last
    reading in contact to the next, :func:`drive_crossings`): no reading falls in the play, whatever the
    time between the readings (with jittered stamps two readings spanned 10.9 ms at a median period of
    5.7 ms)."""
    return bool(np.median(samples) < 2)


def drive_crossings(pr: Problem, model: Model) -> tuple[np.ndarray, np.ndarray]:
    """The model's motor side crossing its whole play (:func:`crossings`), run along ``pr``'s record
    (:func:`shooting.drive_states`): each crossing's samples (from the last contact to the next, 1 where
    it crosses between two readings) and its duration [s]."""
    rec, vec = pr.rec, model.vectors()
    drive = vec.truth.drive_vector()
    side = shooting.drive_states(vec.pp, drive, rec.t, shooting.applied_commands(vec, rec),
                                 pr.blocks[0][1].motion)[:, 2]
    before, after = crossings(side)
    return after - before, rec.t[after] - rec.t[before]


def widest_play(rec: Record) -> tuple[float, float, float] | None:
    """The widest encoder play [m] the readings allow, with the median time [s] over which they turn and the
    fastest speed [m/s] they show (over SPEED_SPAN_S): behind a play the encoder reads nothing new once the
    cart turns, until it has crossed the play, and the cart crosses it no faster than it ever moves; so each
    turn of the readings (from their last change one way to their first change the other) lasts at least the
    play over that speed. The play allowed is that speed times the median turn, plus two counts of rounding
    (a real cart's log was fitted with a 68 mm play where its readings turned within 20 ms at a median turn
    and never moved faster than 0.9 m/s: 18 mm at most). On the valid readings; None where they turn fewer
    than three times."""
    _, x, t, moves = valid_moves(rec)
    turns = np.flatnonzero(np.diff(np.sign(np.diff(x)[moves])) != 0.0)
    if len(turns) < 3:
        return None
    turn = float(np.median(t[moves[turns + 1] + 1] - t[moves[turns]]))
    n = max(1, int(round(SPEED_SPAN_S / rec.dt)))
    fastest = float(np.max(np.abs(x[n:] - x[:-n]) / (t[n:] - t[:-n])))
    return fastest * turn + 2 * rec.x_resolution, turn, fastest


def smallest_play(rec: Record) -> float:
    """The smallest play [m] the ladder keeps: PLAY_COUNTS encoder counts (below, the readings' rounding)."""
    return PLAY_COUNTS * rec.x_resolution


def contradictions(pr: Problem, model: Model, name: str) -> list[str]:
    """Why the data refute the fitted effect ``name`` (empty when nothing does)."""
    rec = pr.rec
    why: list[str] = []
    if name == 'deadzone':
        low = smallest_moving_command(rec)
        if low is not None and model['deadzone_V'] >= low:
            why.append(f'deadzone {model["deadzone_V"]:.3g} V is not below {low:.3g} V, a command that moved the cart')
    if name == 'saturation':
        share = float(np.mean(np.abs(rec.u) > model['saturation_V']))
        if share < MIN_CLIPPED:
            why.append(f'saturation at {model["saturation_V"]:.3g} V clips {100 * share:.2g} % of the commands '
                       f'(needs {100 * MIN_CLIPPED:g} %)')
        above = sorted((u, s) for u, s in steady_speeds(rec) if u > model['saturation_V'])
        if len(above) >= 2 and above[-1][1] > 1.05 * above[0][1] and above[-1][0] > 1.05 * above[0][0]:
            why.append(f'saturation at {model["saturation_V"]:.3g} V, but the steady speed still grew from '
                       f'{above[0][1]:.3g} m/s at {above[0][0]:.3g} V to {above[-1][1]:.3g} m/s '
                       f'at {above[-1][0]:.3g} V')
    if name == 'delay':
        lag = response_lag(rec)
        if model['input_delay_s'] > lag + 2 * rec.dt:
            why.append(f'delay {model["input_delay_s"] * 1e3:.3g} ms exceeds the lag at which the cart answers the '
                       f'command ({lag * 1e3:.3g} ms)')
    if name == 'cogging' and np.ptp(rec.x) < RIPPLE_PERIODS * model['cogging_period_m']:
        why.append(f'cogging period {model["cogging_period_m"] * 1e3:.3g} mm: fewer than {RIPPLE_PERIODS:g} periods '
                   f'over the travel ({np.ptp(rec.x) * 1e3:.3g} mm)')
    if name == 'backlash':
        if model['backlash_m'] < smallest_play(rec):
            why.append(f'play {model["backlash_m"] * 1e3:.3g} mm is below two encoder counts (quantization)')
        elif (limit := widest_play(rec)) is not None and model['backlash_m'] > limit[0]:
            why.append(f'play {model["backlash_m"] * 1e3:.3g} mm: the readings turn within {limit[1] * 1e3:.3g} ms '
                       f'(median of their turns) and never move faster than {limit[2]:.3g} m/s, so the encoder '
                       f'crosses {limit[0] * 1e3:.3g} mm at most')
    if name == 'drive_backlash' and not play_closed(model):
        if model['drive_backlash_m'] < smallest_play(rec):
            why.append(f'drive play {model["drive_backlash_m"] * 1e3:.3g} mm is below two encoder counts '
                       f'(quantization)')
        samples, seconds = drive_crossings(pr, model)
        if len(samples) < 3:
            why.append(f'the motor side crosses its play at {len(samples)} reversals of the drive force '
                       f'(needs 3)')
        elif unseen(samples):
            why.append(f'the motor side crosses its play in {np.median(seconds) * 1e3:.3g} ms (median over '
                       f'{len(samples)} reversals), between two readings: the data cannot show it')
    return why


#: the parameters that give an effect its size (zero = no effect)
SIZE = {'deadzone': ('deadzone_V',), 'delay': ('input_delay_s',), 'cogging': ('cogging_sin_N', 'cogging_cos_N'),
        'asymmetry': ('asymmetry', 'asymmetry_viscous_Ns_per_m'), 'offset': ('offset_N',),
        'sensor_bias': ('bias_theta_rad',), 'backlash': ('backlash_m',), 'drive_backlash': ('drive_backlash_m',)}


def play_closed(model: Model) -> bool:
    """Whether ``model``'s drive has its play held closed (CLOSED_PLAY): a compliant contact without play."""
    if 'drive_backlash' not in model.effects:
        return False
    p = model.param('drive_backlash_m')
    return not p.free and p.value <= CLOSED_PLAY


def size_params(model: Model, name: str) -> tuple:
    """The parameters that give effect ``name`` its size in ``model`` (:data:`SIZE`); a drive whose play is
    held closed has no play to tell from zero: its motor side gives it its size."""
    return ('drive_mass_kg',) if name == 'drive_backlash' and play_closed(model) else SIZE.get(name, ())


def unresolved(model: Model, std: dict, name: str) -> list[str]:
    """The effect's size is not told from zero: every size parameter (:func:`size_params`) within two
    standard errors."""
    names = size_params(model, name)
    stds = [std.get(k) for k in names]
    if not stds:
        return []
    if any(s is None or not math.isfinite(s) for s in stds):
        return ['its size has no standard error (the data do not determine it)']
    sizes = [(k, model[k], float(s or 0.0)) for k, s in zip(names, stds)]
    if all(abs(v) <= 2 * s for _, v, s in sizes):
        return ['its size is within two standard errors of zero (' +
                ', '.join(f'{k} = {v:.3g} +/- {s:.2g}' for k, v, s in sizes) + ')']
    return []


def near(value: float, ref: float, s) -> bool:
    """``value`` within UNDO_SIGMA standard errors ``s`` of ``ref`` (a correction not told from the value it
    corrects); False where ``s`` is missing or not finite."""
    return s is not None and math.isfinite(s) and abs(value - ref) <= UNDO_SIGMA * s


def uncorrected(model: Model, std: dict, before: Model, names) -> list[str]:
    """A plant correction not told from the value it corrects (``before``'s: :func:`near`), or without a
    standard error (alpha 0.1 % low, 1.5 standard errors, kept on a clean cart for 0.06 count)."""
    out = []
    for n in names:
        s = std.get(n)
        if s is None or not math.isfinite(s):
            out.append(f'{n} has no standard error (the data do not determine it)')
        elif near(model[n], before[n], s):
            out.append(f'{n} = {model[n]:.4g} +/- {s:.2g} {model.param(n).unit} is within {UNDO_SIGMA:g} standard '
                       f'errors of {before[n]:.4g}: not told from it')
    return out


def rest_offset(theta: np.ndarray) -> float:
    """The mean angle's offset [rad] from the equilibrium nearest to it (upright 0, hanging +/-pi): where a
    biased angle encoder puts a pendulum at rest (a hanging one's mean is near -pi, not a bias of -3 rad
    against the bias's bound of 1 rad)."""
    mean = float(np.mean(theta))
    return mean - math.pi * round(mean / math.pi)


#: parameters whose lower bound is the simpler law itself, not a limit of physics: in the coulomb law,
#: static friction no higher than the Coulomb level is Coulomb friction without stiction (the data saw no
#: sticking); the laws with a Stribeck curve take a static level below it (a friction that rises with speed)
NESTED_AT_LOWER = ('Fs_excess',)


def no_static_level(model: Model, p) -> bool:
    """True when ``p`` is Fs_excess and puts the static level Fc + Fs_excess at 0 or below (no static
    friction at all: :func:`~ipfric_core.ident.effects.static_level`)."""
    return p.name == 'Fs_excess' and static_level(model['Fc'], p.value) <= 1e-3 * PARAMS[p.name].typical


def bound_params(model: Model) -> list:
    """The fitted parameters of ``model`` that end on a bound of their range; but for
    :data:`NESTED_AT_LOWER` at their lower one; Fs_excess also where :func:`no_static_level`."""
    def refutes(p) -> bool:
        tol = 1e-3 * PARAMS[p.name].typical
        if no_static_level(model, p):
            return True
        return p.at_bound(tol) and not (p.name in NESTED_AT_LOWER and p.value - p.lo <= tol)
    return [p for p in model.free if refutes(p)]


def on_bounds(model: Model) -> list[str]:
    """Why a fitted parameter of ``model`` refutes it: it ends on a bound of its range (a bound reached
    means the law or the effect is refuted there; :func:`bound_params`)."""
    def bound(p) -> str:
        if no_static_level(model, p):
            return f'-Fc = {-model["Fc"]:.4g} N: no static friction'
        return f'[{p.lo:g}, {p.hi:g}]'
    return [f'{p.name} = {p.value:.4g} {p.unit} ends on its bound {bound(p)}' for p in bound_params(model)]


def untold(model: Model, std: dict) -> list[str]:
    """A friction level that is not told from zero refutes the model: a real cart slides against a
    Coulomb level (Fc within two standard errors of 0 means the model makes up for something else)."""
    s = std.get('Fc')
    if 'Fc' in {p.name for p in model.free} and s is not None and math.isfinite(s) and model['Fc'] <= 2 * s:
        return [f'Fc = {model["Fc"]:.3g} +/- {s:.2g} N is not told from zero: a real cart slides against a '
                f'Coulomb level; the model makes up for something else']
    return []


def reversals(rec: Record, counts: int = 3) -> int:
    """How often the cart reverses its travel: each reversal passes zero speed, and then the cart travels
    the other way by ``counts`` encoder counts at least (the encoder's dither at rest is not one)."""
    step = counts * rec.x_resolution
    x = rec.x[rec.valid_mask]
    d, ext, n = 0.0, float(x[0]) if len(x) else 0.0, 0
    for v in x.tolist():
        if d == 0.0:
            if abs(v - ext) >= step - 0.5 * rec.x_resolution:
                d, ext = math.copysign(1.0, v - ext), v
        elif (v - ext) * d > 0.0:
            ext = v
        elif (ext - v) * d >= step - 0.5 * rec.x_resolution:      # whole counts, whatever the rounding
            n, d, ext = n + 1, -d, v
    return n


def never_starts(rec: Record, model: Model) -> list[str]:
    """Why ``model``'s cart could not start where the record's did: its static friction (eq. 5 with the
    direction dependence, :func:`~ipfric_core.physics.friction.holding_margin`) holds the cart both ways
    against the force the drive gives at rest, alpha times the command through the model's deadzone and
    saturation, with the track's forces (offset, cogging amplitude) added at their largest, while the
    record shows the cart starting from rest (:func:`stops_and_starts`, then travelling three counts within
    BREAKAWAY_S) or reversing its travel (:func:`reversals`: through zero speed, where static friction holds
    too). The command is the record's largest, and for the start from rest it did least to cause, the largest
    within BREAKAWAY_S of that start (a PID cart's log kept a static level of 24.5 N, below the 28 N of its largest
    command, where it had travelled 16 counts from rest under 0.63 V, 1.5 N). A model that cannot move the
    cart where it moved is not the rig's, whatever its error on windows that start moving. Only for the laws
    that stick (coulomb, exponential: the dynamic law's bristles creep below the static level), without a
    drive play (its contact's impacts push harder than the drive's force), on the cart alone (a pendulum's
    swing pushes the cart too)."""
    vec = model.vectors()
    if rec.theta is not None or not sticks(vec.fp) or 'drive_backlash' in model.effects:
        return []
    tr = vec.truth
    track = abs(model.get('offset_N')) + math.hypot(model.get('cogging_sin_N'), model.get('cogging_cos_N'))

    def push(volts: float) -> float:
        """The largest force [N] the drive and the track give at rest under commands up to ``volts``."""
        return model['alpha'] * input_effects(volts, tr.deadzone_V, tr.saturation_V) + track

    def holds(force: float) -> bool:
        return holding_margin(vec.fp, force) < 0.0 and holding_margin(vec.fp, -force) < 0.0
    travel = 2.5 * rec.x_resolution                        # three counts from the still reading
    starts = [still for still, _ in stops_and_starts(rec)
              if np.max(np.abs(rec.x[still:np.searchsorted(rec.t, rec.t[still] + BREAKAWAY_S)] - rec.x[still]))
              >= travel]
    most = float(np.max(np.abs(rec.u)))
    if holds(push(most)):
        turns = reversals(rec)
        if starts or turns:
            seen = ' and '.join(w for w in (f'started from rest {len(starts)} times' if starts else '',
                                            f'reversed its travel {turns} times' if turns else '') if w)
            return [f'static friction (up to {static_limit(vec.fp):.4g} N) holds the cart against every command '
                    f'of the record (at rest the drive gives at most {push(most):.4g} N: alpha '
                    f'{model["alpha"]:.4g} N/V times {input_effects(most, tr.deadzone_V, tr.saturation_V):.4g} V'
                    + (f', the track {track:.3g} N' if track > 0.0 else '') + f'), yet the cart {seen}']
    if starts:      # the weakest start: the smallest largest command within BREAKAWAY_S of it
        volts, still = min((float(np.max(np.abs(rec.u[np.abs(rec.t - rec.t[k]) <= BREAKAWAY_S]))), k)
                           for k in starts)
        if holds(push(volts)):
            return [f'static friction (up to {static_limit(vec.fp):.4g} N) holds the cart against the drive at '
                    f't = {rec.t[still]:.4g} s (at most {push(volts):.4g} N within {BREAKAWAY_S:g} s: commands up '
                    f'to {volts:.4g} V), yet the cart started from rest there and travelled three counts']
    return []


def unheld_travels(rec: Record, model: Model) -> list[tuple[float, int, int]]:
    """How far [m] a cart without static friction must leave the one encoder count it stood still in over
    each stop (first .. last sample, :func:`stops`) of ``rec``, at the least, with the stop: ``model``'s drive
    force (alpha times the command through its delay, lag, deadzone and saturation, eq. 2) and its track force
    (offset, cogging at the stop's reading) integrated twice from the stop's start, with the pendulum's
    reaction (the cart's equation of paper eqs. 1-2: (M + m) x'' + m l (theta' cos(theta))' = F, so m l
    (sin(theta) - sin(theta_0)) after two integrals), against every start speed (a line in time, which takes
    theta_0' too); within the stop the cart moves less than a count (plus an encoder play) w, so the viscous
    term (beta + eps) x' gives at most (beta + eps) w t, and that much is allowed, as is the angle's
    rounding. 0 where the stop is consistent with no static friction at all."""
    tr = model.vectors().truth
    volts = drive_means(rec.t, rec.u, tr.input_delay_s, tr.input_lag_s)
    forces = tr.force_vector()
    w = rec.x_resolution + model.get('backlash_m')
    mass, swing = model['M'], 0.0
    theta = rec.theta if model.pendulum else None
    if theta is not None:
        mass += model['m']
        swing = model['m'] * model['l'] * rec.theta_resolution      # the angle's rounding, twice half a count
    out = []
    for first, last in stops(rec):
        idx = np.arange(first, last + 1)
        t = rec.t[idx] - rec.t[first]
        force = np.array([model['alpha'] * input_effects(v, tr.deadzone_V, tr.saturation_V)
                          for v in volts[idx]]) + undeclared_force(forces, rec.x[first], 0.0)
        h = np.diff(t)
        impulse = np.concatenate([[0.0], np.cumsum(force[:-1] * h)])
        travel = np.concatenate([[0.0], np.cumsum(impulse[:-1] * h + 0.5 * force[:-1] * h ** 2)])
        if theta is not None:
            travel -= model['m'] * model['l'] * (np.sin(theta[idx]) - math.sin(theta[first]))
        valid = rec.valid_mask[idx]
        g, tv = travel[valid] / mass, t[valid]
        slack = (model['beta'] + model['eps']) * w * tv / mass
        # min over the start speed a of max_k |g_k - a t_k| - slack_k: a linear programme in (a, e)
        ones = np.ones_like(tv)
        res = linprog([0.0, 1.0], A_ub=np.vstack([np.column_stack([-tv, -ones]), np.column_stack([tv, -ones])]),
                      b_ub=np.concatenate([slack - g, slack + g]), bounds=[(None, None), (None, None)],
                      method='highs')
        out.append((max(float(res.x[1]) - w - swing / mass, 0.0) if res.success else 0.0, first, last))
    return out


def never_holds(recs, model: Model) -> list[str]:
    """Why ``model``'s cart could not stand still where the records' did (``recs``: the estimation and the
    validation parts; a stop is what the data show, in either): a law without static friction (the viscous
    law) moves the cart under any force, and the records show stops (:func:`stops`) over which the forces of
    the drive, the track and the pendulum would have moved it beyond HOLD_COUNTS encoder counts
    (:func:`unheld_travels`; the ESP32 cart's log at 0.1 Hz stood still for 0.11 s under commands of up to 4.6
    V, where a cart without static friction leaves its count by 13 counts). Not judged with a drive play (its
    motor side takes the force across the play while the cart stands)."""
    if model.law != 'viscous' or 'drive_backlash' in model.effects:
        return []
    moved = [(travel / rec.x_resolution, rec.t[a], rec.t[b] - rec.t[a])
             for rec in recs for travel, a, b in unheld_travels(rec, model)]
    beyond = [m for m in moved if m[0] >= HOLD_COUNTS]
    if not beyond:
        return []
    counts, start, still = max(beyond)
    return [f'the viscous law has no static friction, yet the cart stood still at {len(beyond)} of {len(moved)} '
            f'stops where the drive\'s force would have moved it (at t = {start:.4g} s for {still:.3g} s: '
            f'{counts:.3g} encoder counts beyond its count at the least)']


def unfit(rec: Record, model: Model, std: dict | None = None, val: Record | None = None) -> list[str]:
    """Why a fitted ``model`` cannot stand as a step, whatever its error: a parameter on its bound
    (:func:`on_bounds`), a Coulomb level not told from zero by its standard errors ``std`` (:func:`untold`;
    not checked without them), a static friction that never lets the cart start in the estimation part
    ``rec`` (:func:`never_starts`) and no static friction where the cart stood still under force in it or in
    the validation part ``val`` (:func:`never_holds`)."""
    return (on_bounds(model) + (untold(model, std) if std else []) + never_starts(rec, model)
            + never_holds([rec] + ([val] if val is not None else []), model))
