"""Time integration of the nonlinear cart-pendulum with exact stick-slip.

:class:`Simulator` advances the plant over one sample with the voltage held constant
(zero-order hold). Smooth laws are integrated with classical RK4 substeps. A sticking
law (coulomb, exponential without smoothing) is integrated as a hybrid system:

- sliding: RK4 with sgn(x') fixed to the direction of motion; when x' reaches zero
  inside a substep the crossing instant is located (Brent's method on the RK4 step
  length), the state is placed there with x' = 0, and the cart sticks if static
  friction can hold it (``friction.holds`` on ``plant.held_force``, which includes the
  pendulum's reaction), otherwise it slides the other way;
- stuck: x, x' are frozen, the pendulum swings with theta'' = 3 g sin(theta)/(4 l); the
  breakaway instant where |held force| reaches mu_s F_N is located the same way.

Events are located, never stepped over, so the motion neither chatters around v = 0
nor stalls.

The integrator is compiled by numba (:func:`advance`) and calls the scalar physics of
:mod:`ipfric_core.physics.plant` and :mod:`ipfric_core.physics.friction`; its state is a 5-tuple
(x, theta, x', theta', z) and a mode (stuck 0/1, direction of motion, event count).
"""
from __future__ import annotations

import math

from .compiled import compiled
from .friction import (
    DYNAMIC,
    FP_EPS,
    FP_MODEL,
    FP_SIGMA0,
    FP_SIGMA1,
    bristle_relaxation,
    friction_force,
    holding_margin,
    holds,
    sticks,
)
from .plant import (
    NO_EXTRA_FORCE,
    CartPendulum,
    beyond_play,
    drive_contact_force,
    force_input,
    held_force,
    motor_force,
    motor_side_free,
    rates,
    stuck_theta_acceleration,
    undeclared_force,
)

__all__ = ['held', 'advance', 'advance_drive', 'friction_now', 'Simulator']

MAX_EVENTS = 64  # per substep; a guard, never reached in normal motion
XTOL = 1e-13     # event time tolerance [s]
CONTACT_STEPS = 40       # steps per period of the drive's contact oscillation (and of the bristles')
MAX_BRISTLE_STEPS = 100   # steps of the dynamic law within one substep at most (stiffer bristles than a
#                           record's substep can carry diverge, and their fit fails on its own)
EVENT_SPLIT = 16         # finer steps of a drive's step at an edge of its contact, a stop or a breakaway
NO_DRIVE = (0.0, 0.0, 0.0, 0.0)   # (play [m], motor-side mass [kg], stiffness [N/m], damping [N s/m]): rigid


@compiled
def rk4_slide(pp, fp, ef, s, h, voltage, d):
    """One RK4 step of length ``h`` [s] of the sliding motion with sgn(x') = ``d``."""
    k1 = rates(pp, fp, ef, s, voltage, d)
    s2 = (s[0] + 0.5 * h * k1[0], s[1] + 0.5 * h * k1[1], s[2] + 0.5 * h * k1[2],
          s[3] + 0.5 * h * k1[3], s[4] + 0.5 * h * k1[4])
    k2 = rates(pp, fp, ef, s2, voltage, d)
    s3 = (s[0] + 0.5 * h * k2[0], s[1] + 0.5 * h * k2[1], s[2] + 0.5 * h * k2[2],
          s[3] + 0.5 * h * k2[3], s[4] + 0.5 * h * k2[4])
    k3 = rates(pp, fp, ef, s3, voltage, d)
    s4 = (s[0] + h * k3[0], s[1] + h * k3[1], s[2] + h * k3[2], s[3] + h * k3[3], s[4] + h * k3[4])
    k4 = rates(pp, fp, ef, s4, voltage, d)
    c = h / 6.0
    return (s[0] + c * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]),
            s[1] + c * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]),
            s[2] + c * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2]),
            s[3] + c * (k1[3] + 2 * k2[3] + 2 * k3[3] + k4[3]),
            s[4] + c * (k1[4] + 2 * k2[4] + 2 * k3[4] + k4[4]))


@compiled
def rk4_stuck(pp, s, h):
    """One RK4 step of the pendulum over the resting cart (x, x' frozen)."""
    th, w = s[1], s[3]
    k1t, k1w = w, stuck_theta_acceleration(pp, th)
    k2t, k2w = w + 0.5 * h * k1w, stuck_theta_acceleration(pp, th + 0.5 * h * k1t)
    k3t, k3w = w + 0.5 * h * k2w, stuck_theta_acceleration(pp, th + 0.5 * h * k2t)
    k4t, k4w = w + h * k3w, stuck_theta_acceleration(pp, th + h * k3t)
    return (s[0], th + h / 6.0 * (k1t + 2 * k2t + 2 * k3t + k4t), 0.0,
            w + h / 6.0 * (k1w + 2 * k2w + 2 * k3w + k4w), s[4])


@compiled
def held(pp, ef, s, voltage):
    """Force static friction must cancel to keep the cart at rest in state ``s`` [N]."""
    return held_force(pp, s[1], s[3], motor_force(pp, voltage, 0.0) + undeclared_force(ef, s[0], 0.0))


@compiled
def _event(kind, pp, fp, ef, s, tau, voltage, d, level):
    """Event functions of the step length tau [s], each changing sign at the event.

    kind 0 (breakaway): the holding margin of the held force after tau stuck; kind 1 (stop):
    x' d after tau sliding, with ``level`` = |x'| at tau = 0.
    """
    if kind == 0:
        return holding_margin(fp, held(pp, ef, rk4_stuck(pp, s, tau), voltage))
    if tau <= 0.0:
        return level
    return rk4_slide(pp, fp, ef, s, tau, voltage, d)[2] * d


@compiled
def _locate(kind, pp, fp, ef, s, hi, voltage, d, level):
    """Root in (0, hi) of :func:`_event` by Brent's method (as scipy's brentq), tolerance XTOL."""
    xpre, xcur = 0.0, hi
    fpre = _event(kind, pp, fp, ef, s, xpre, voltage, d, level)
    fcur = _event(kind, pp, fp, ef, s, xcur, voltage, d, level)
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    xblk = fblk = spre = scur = 0.0
    for _ in range(200):
        if fpre != 0.0 and fcur != 0.0 and (fpre < 0.0) != (fcur < 0.0):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (XTOL + 4.44e-16 * abs(xcur)) / 2
        sbis = (xblk - xcur) / 2
        if fcur == 0.0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2 * abs(stry) < min(abs(spre), 3 * abs(sbis) - delta):
                spre, scur = scur, stry
            else:
                spre, scur = sbis, sbis
        else:
            spre, scur = sbis, sbis
        xpre, fpre = xcur, fcur
        if abs(scur) > delta:
            xcur += scur
        else:
            xcur += delta if sbis > 0 else -delta
        fcur = _event(kind, pp, fp, ef, s, xcur, voltage, d, level)
    return xcur


@compiled
def _settle(pp, fp, ef, s, voltage, events):
    """At x' = 0: stick if static friction holds, else slide along the held force."""
    applied = held(pp, ef, s, voltage)
    if holds(fp, applied):
        return (s[0], s[1], 0.0, s[3], s[4]), (1.0, 0.0, events + 1.0)
    return s, (0.0, math.copysign(1.0, applied), events + 1.0)


@compiled
def _advance_hybrid(pp, fp, ef, s, mode, h, voltage):
    stuck, d, events = mode
    remaining = h
    for _ in range(MAX_EVENTS):
        if remaining <= 0.0:
            return s, (stuck, d, events)
        if stuck != 0.0:
            applied = held(pp, ef, s, voltage)
            if not holds(fp, applied):
                stuck, d, events = 0.0, math.copysign(1.0, applied), events + 1.0
                continue
            new = rk4_stuck(pp, s, remaining)
            if holds(fp, held(pp, ef, new, voltage)):
                return new, (stuck, d, events)
            tb = _locate(0, pp, fp, ef, s, remaining, voltage, 0.0, 0.0)
            tb = min(remaining, tb * (1 + 1e-9) + 1e-15)  # step just past the threshold
            s = rk4_stuck(pp, s, tb)
            remaining -= tb
            stuck, d, events = 0.0, math.copysign(1.0, held(pp, ef, s, voltage)), events + 1.0
            continue
        if d == 0.0:
            if s[2] == 0.0:
                s, (stuck, d, events) = _settle(pp, fp, ef, s, voltage, events)
                continue
            d = math.copysign(1.0, s[2])
        new = rk4_slide(pp, fp, ef, s, remaining, voltage, d)
        if new[2] * d > 0.0:
            return new, (stuck, d, events)
        start = max(abs(s[2]), 1e-300)  # the motion starts along d by construction
        tc = _locate(1, pp, fp, ef, s, remaining, voltage, d, start)
        s = rk4_slide(pp, fp, ef, s, tc, voltage, d)
        s = (s[0], s[1], 0.0, s[3], s[4])
        remaining -= tc
        s, (stuck, d, events) = _settle(pp, fp, ef, s, voltage, events)
    # Guard (more than MAX_EVENTS transitions in one substep): finish it sliding.
    return rk4_slide(pp, fp, ef, s, remaining, voltage, d), (stuck, d, events)


@compiled
def bristle_step(pp, fp, v: float, h: float) -> float:
    """Largest RK4 step [s] of the dynamic law (eqs. 10-11) at speed ``v`` [m/s]: ``h``, CONTACT_STEPS
    per period 2 pi sqrt(M / sigma0) of the bristles' oscillation with the cart, and at most 1 over the
    bristles' relaxation rate sigma0 |v| / g(v) (:func:`bristle_relaxation`) and the damping rate
    (sigma1 + eps) / M (RK4 is stable to 2.8 over a rate); no more than MAX_BRISTLE_STEPS steps in ``h``.
    ``h`` for the other laws."""
    if fp[FP_MODEL] != DYNAMIC:
        return h
    step = min(h, 2.0 * math.pi * math.sqrt(pp[0] / fp[FP_SIGMA0]) / CONTACT_STEPS)
    rate = max(bristle_relaxation(fp, v), (fp[FP_SIGMA1] + fp[FP_EPS]) / pp[0])
    if rate * step > 1.0:
        step = 1.0 / rate
    return max(step, h / MAX_BRISTLE_STEPS)


@compiled
def advance(pp, fp, ef, s, mode, voltage, dt, substep):
    """State and mode after ``dt`` [s] with ``voltage`` [V] held, in RK4 substeps <= ``substep``
    (shorter where the dynamic law's bristles are stiff: :func:`bristle_step`)."""
    n = max(1, math.ceil(dt / substep - 1e-9))
    h = dt / n
    hybrid = sticks(fp)
    for _ in range(n):
        if hybrid:
            s, mode = _advance_hybrid(pp, fp, ef, s, mode, h, voltage)
        else:
            rest = h
            while rest > 1e-12 * h:
                hk = min(rest, bristle_step(pp, fp, s[2], rest))
                s = rk4_slide(pp, fp, ef, s, hk, voltage, mode[1])
                rest -= hk
    return s, mode


@compiled
def drive_step(dp, mass_cart: float, substep: float) -> float:
    """Largest step [s] of :func:`advance_drive`: ``substep``, and CONTACT_STEPS per period of the
    contact oscillation 2 pi sqrt(m_r / k) of the motor side (mass dp[1]) against the cart
    (``mass_cart``), m_r their reduced mass."""
    reduced = dp[1] * mass_cart / (dp[1] + mass_cart)
    return min(substep, 2.0 * math.pi * math.sqrt(reduced / dp[2]) / CONTACT_STEPS)


@compiled
def advance_drive(pp, fp, ef, s, mode, drive, voltage, dt, substep, dp):
    """:func:`advance` for a drive with play (backlash) between motor and cart.

    Two-mass drive, ``dp`` = (play [m], motor-side mass [kg], contact stiffness [N/m], contact
    damping [N s/m]): the motor side (rotor and gears reflected to the rack) takes the motor force
    of eq. (2) (:func:`plant.motor_side_free`); the cart gets only the contact force
    :func:`plant.drive_contact_force` (none inside the play) besides friction and its other
    forces; the encoder reads the cart. ``drive`` = (d [m], vb [m/s]): motor side minus cart, and
    the motor side's speed. Each step (:func:`drive_step`, :func:`_drive_step`) holds the contact force
    at the mean of its values at the start and at the end of a first pass (Heun: the cart by one Euler
    step of its rates, or at rest where static friction holds it; the motor side exactly), then advances
    the cart by :func:`advance` (exact stick-slip) and the motor side exactly. A step in which the contact
    closes or opens (its force jumps by the damping's share) or the cart stops or breaks away is done
    again in EVENT_SPLIT steps. Returns (state, mode, drive). Against LSODA (tests/physics/test_engines.py,
    a 150 Hz contact, commands held 10 ms, 3 s of stick-slip): 10.7 um RMS, where the same steps without
    the finer ones at the contact's edges left 36 um; a first pass by a whole :func:`advance` of the cart
    cost 1.7 times as much and moved the cart by nm.
    """
    d, vb = drive
    n = max(1, math.ceil(dt / drive_step(dp, pp[0], substep) - 1e-9))
    h = dt / n
    for _ in range(n):
        s1, mode1, d1, vb1 = _drive_step(pp, fp, ef, s, mode, d, vb, voltage, h, dp)
        if mode1[2] != mode[2] or beyond_play(dp, d) != beyond_play(dp, d1):   # an edge: finer steps
            for _ in range(EVENT_SPLIT):
                s, mode, d, vb = _drive_step(pp, fp, ef, s, mode, d, vb, voltage, h / EVENT_SPLIT, dp)
        else:
            s, mode, d, vb = s1, mode1, d1, vb1
    return s, mode, (d, vb)


@compiled
def _drive_step(pp, fp, ef, s, mode, d, vb, voltage, h, dp):
    """One step of :func:`advance_drive` of length ``h`` [s]: (state, mode, d, vb) after it."""
    on_cart = force_input(pp)
    f0 = drive_contact_force(dp, d, vb - s[2])
    if mode[0] != 0.0 and holds(fp, held(on_cart, ef, s, f0)):
        moved, v1 = 0.0, 0.0
    else:
        a = rates(on_cart, fp, ef, s, f0, mode[1] if mode[1] != 0.0 else math.copysign(1.0, s[2]))[2]
        moved, v1 = h * s[2] + 0.5 * a * h * h, s[2] + a * h
    dx, vb1 = motor_side_free(pp, dp[1], vb, voltage - f0 / pp[4], h)
    f = 0.5 * (f0 + drive_contact_force(dp, d + dx - moved, vb1 - v1))
    s1, mode = advance(on_cart, fp, ef, s, mode, f, h, h)
    dx, vb = motor_side_free(pp, dp[1], vb, voltage - f / pp[4], h)
    return s1, mode, d + dx - (s1[0] - s[0]), vb


@compiled
def friction_now(pp, fp, ef, s, mode, voltage):
    """Friction force on the cart in state ``s`` and ``mode`` [N] (static while stuck)."""
    if mode[0] != 0.0:
        return -held(pp, ef, s, voltage)
    return friction_force(fp, s[2], s[4], mode[1])


class Simulator:
    """Stateful integrator of one plant.

    Parameters
    ----------
    model : CartPendulum
    state0 : sequence
        Initial (x, theta, x', theta'[, z]) [SI]; missing z defaults to 0.
    substep : float
        Largest RK4 step [s] (default 0.25 ms, four per 1 kHz sample).
    extra_force : (cogging [N], cogging period [m], asymmetry [N]), optional
        Forces on the cart the friction model does not know (:func:`plant.undeclared_force`).
    drive : (play [m], motor-side mass [kg], contact stiffness [N/m], contact damping [N s/m]), optional
        A drive with play between motor and cart (:func:`advance_drive`); play 0 = rigid. The
        motor side starts at rest in the middle of the play.
    """

    def __init__(self, model: CartPendulum, state0, substep: float = 2.5e-4,
                 extra_force: tuple = NO_EXTRA_FORCE, drive: tuple = NO_DRIVE):
        self.model = model
        s = [float(v) for v in state0][:model.n_states]
        self._s = tuple(s + [0.0] * (5 - len(s)))
        self._mode = (0.0, 0.0, 0.0)  # stuck, direction of motion of a sticking law, events
        self.t = 0.0
        self.substep = float(substep)
        self.extra_force = tuple(float(v) for v in extra_force)
        self._pp, self._fp = model.vector, model.friction.vector
        self.drive = tuple(float(v) for v in drive)
        self._drive = (0.0, 0.0)  # motor side minus cart [m], its speed [m/s]

    @property
    def state(self) -> list:
        """(x, theta, x', theta'[, z]) [SI]."""
        return list(self._s[:self.model.n_states])

    @property
    def state_tuple(self) -> tuple:
        """The integrator's full state (x, theta, x', theta', z) [SI], z = 0 for laws without it."""
        return self._s

    @property
    def mode(self) -> tuple:
        """The integrator's mode (stuck 0/1, direction of motion of a sticking law, events)."""
        return self._mode

    @property
    def stuck(self) -> bool:
        """True while static friction holds the cart."""
        return self._mode[0] != 0.0

    @property
    def events(self) -> int:
        """Number of stick/slip transitions so far."""
        return int(self._mode[2])

    def held_force(self, s, voltage: float) -> float:
        """Force static friction must cancel at rest [N] (with x' = 0)."""
        return held(self._pp, self.extra_force, (float(s[0]), float(s[1]), 0.0, float(s[3]), 0.0), voltage)

    def friction_force(self, voltage: float) -> float:
        """Friction force on the cart in the current state [N]; with a drive with play, the force
        of its contact (:func:`plant.drive_contact_force`) takes the motor force's place."""
        if self.drive[0] > 0.0:
            d, vb = self._drive
            pp = self._pp
            return friction_now(force_input(pp), self._fp, self.extra_force, self._s,
                                self._mode, drive_contact_force(self.drive, d, vb - self._s[2]))
        return friction_now(self._pp, self._fp, self.extra_force, self._s, self._mode, voltage)

    def step(self, voltage: float, dt: float) -> None:
        """Advance by ``dt`` [s] with the voltage held at ``voltage`` [V]."""
        if self.drive[0] > 0.0:
            self._s, self._mode, self._drive = advance_drive(
                self._pp, self._fp, self.extra_force, self._s, self._mode, self._drive, float(voltage),
                float(dt), self.substep, self.drive)
        else:
            self._s, self._mode = advance(self._pp, self._fp, self.extra_force, self._s, self._mode,
                                          float(voltage), float(dt), self.substep)
        self.t += dt
