"""Randomised independent identification campaign: rigs, effects, experiments drawn at random.

Like ``rigsim`` this module shares NOTHING with ``ipfric_core``: its own integrator (fixed-step
RK4 with located velocity zeros and exact sticking), its own friction and effect formulas, its
own controller, velocity estimators and LQR design. Every case is drawn from
``numpy.random.default_rng([seed, index, attempt])``: the same (seed, index) gives the same
case and the same bytes on disk. ``attempt`` counts redraws of a case whose run left the track
or whose pendulum fell (the first attempt that stays on the track is kept; the truth records it).

SI units throughout: x [m], theta [rad], t [s], voltage [V], force [N].

Plant (paper eq. 1-2; pendulum a uniform rod, centre of mass at l from the pivot; theta from
upright, hanging = pi):
    (M + m) x'' + m l cos(th) th'' - m l sin(th) th'^2 = F + F_fric + F_extra
    (4/3) m l^2 th'' + m l cos(th) x'' - m g l sin(th) = 0
    F = alpha u - beta x'            (u: the voltage reaching the motor)
Cart alone: m = 0 in the dynamics (the pendulum is removed); F_N = M g, else (M + m) g.
Friction (exponential law, gamma = 2), levels in N:
    sliding   F_fric = -(1 + a sgn v) (Fc(x) + (Fs - Fc) exp(-(v/v_s)^2)) sgn v - eps v
    sticking  v = 0 while -(1 - a) Fs(x) <= N <= (1 + a) Fs(x)  (N: force on the cart at x'' = 0)
    Fc(x) = Fc (1 + f b(x)), Fs(x) = Fs + Fc f b(x)   (friction patch; b a C1 bump, 0 elsewhere)
Effects (names as ipfric's library, plus two from outside it):
    deadzone        u = 0 for |V_d| <= dz, V_d - sgn(V_d) dz beyond                 dz [V]
    saturation      the amplifier clips the motor voltage: u = clip(., +-u_max)     u_max [V]
    delay           the force follows the command d seconds later, the command held per
                    sample: V_d(t) = V_j for t_j + d <= t < t_(j+1) + d (0 V before t_0 + d);
                    d need not be a whole number of samples                          d [s]
    cogging         F_extra += A sin(2 pi x / P + phase)                             A [N], P [m]
    asymmetry       friction level (1 + a) forward, (1 - a) backward (static too)   a [-]
    offset          F_extra += F0                                                    F0 [N]
    sensor_bias     the angle encoder reads theta + b                                b [rad]
    drive_backlash  two-mass drive: m_b x_b'' = alpha u - beta x_b' - F_k; the cart is driven
                    by F_k = k (d -+ gap/2) + c (x_b' - x') beyond the play only (pushing only),
                    d = x_b - x; the encoder reads the cart (as rigsim's backlash)
    spring          (outside the library) a cable towards the track centre:
                    F_extra += -k x + F_pre                                          k [N/m], F_pre [N]
    friction_patch  (outside the library) Coulomb level raised by a fraction f on a stretch
                    [x_lo, x_hi] of the track (C1 edges 2 mm wide)                   f [-], x [m]
Chain of the command V (recorded in the CSV, after the controller's own clip): delay ->
deadzone -> saturation -> motor.
Sensors: x and theta rounded to the encoder counts (theta in the encoder's own frame: zero
hanging or upright); sample overruns repeat the previous readings; jittered stamps are the true
sample instants.

Parts of an effect that a declared parameter takes over: a drive's play alone
(``play_contribution_counts_rms``: against its motor side fixed to the cart, a heavier cart;
``closed_contribution_counts_rms``: against the same drive with its play closed, a compliant contact) and a
deadzone beyond the friction (``beyond_friction_counts_rms``: against a Coulomb and static level
higher by alpha dz, what the deadzone is while the cart moves the way it is driven). A spring's
mean pull over the record (``mean_pull_N``, F_pre - k mean(x)) is a constant force
(``mean_pull_contribution_counts_rms``: against the same spring without it).

Contribution of an effect (truth ``contribution_counts_rms``): the recorded command is replayed
from the true state at the start of each 1 s window (multiple shooting), once with every drawn
effect and once without this one; the RMS over all samples of the difference in cart position,
in cart encoder counts (unrounded). With a pendulum its angle and rate follow the true motion
inside the windows (cubic Hermite between samples; an upright pendulum replayed free would
diverge within a window). ``replay_self_error_counts_rms``: the replay with every effect against
the true motion (about 1e-3 count; larger only where the motion is chaotic, e.g. a drive play's
contact knocked at every reversal of a balancing controller). sensor_bias: the difference of
the angle readings, in angle counts.
A declared plant constant made wrong (``plant_error``) gets its contribution the same way (the
declared constant against the true one); a wrong pendulum mass also what one correction of the plant
leaves of everything outside the library (``one_correction_counts_rms``: the best alpha, the best M).

What is drawn (per case): the experiment (cart alone 50 %: ramps, steps with coast-downs,
repositioning moves, pulses, multisines, no theta column or in 30 % a column of literal zeros;
pendulum hanging 20 %: the same open-loop excitation, the angle read from hanging (~0), from
upright (~pi) or from upright wrapped at +-pi; closed loop 30 %: LQR balancing upright with a gain
of this module's own design (random Q, a guessed viscous coefficient), velocities by a filtered
difference (10-50 Hz), a plain difference or an alpha-beta observer, clipped at 5-12 V, no
excitation, a setpoint square wave or a voltage dither; the angle from upright or from hanging
wrapped); the rig (M 0.2-2 kg, m, l, alpha 0.5-3 N/V, beta 1-12 N s/m, Fc 0.05-2 N, static excess,
viscous eps, Stribeck velocity, encoders 1e-5..1e-4 m and 1024-4096 counts a turn); the effect
(none 25 %, each library effect 7.5 %, spring and friction patch 7.5 % each; a second effect in
8 % of the others), its size log-uniform from invisible to obvious; the sample period 1-10 ms,
regular, jittered and/or with overruns (the stamp skips 2-3 periods, then 1-3 readings repeat);
30-120 s; in 12 % one declared constant wrong by 10-40 % (truth ``plant_error``). A hanging
pendulum may swing over the top (its angle then leaves +-pi around its rest): real logs do that.

Files: DIR/<case>/data.csv (t, x, voltage[, theta]), plant.yaml (the declared plant), truth.json:
``spec`` (every drawn value), ``effects`` (each effect's parameters in SI units, ``library``,
``contribution_counts_rms`` over the record and its last 40 % ``..._validation``, the largest
difference), ``contribution_counts_rms`` (name -> counts), ``plant_error``, ``constants``,
``declared_plant``, ``friction`` (levels in N and as coefficients of F_N), ``encoder``, ``timing``,
``controller`` (with the gain K), ``segments`` (the open-loop plan), ``motion``,
``replay_self_error_counts_rms``; DIR/manifest.json lists the cases and their generation times.

CLI (from tests/):  python -m independent.campaign --out DIR --cases N --seed S [--workers W]
API: draw_case(seed, index) -> spec; simulate(spec) -> data; contributions(spec, data);
make_case(seed, index) -> (data, truth); write_case(out_dir, seed, index) -> truth;
generate(out_dir, n_cases, seed, indices=None, workers=1) -> manifest.
"""

import argparse
import json
import math
import time
from pathlib import Path

import numba
import numpy as np
from scipy.optimize import minimize_scalar

from . import rigsim

_jit = numba.njit(cache=True)     # compiled once per machine, into tests/independent/__pycache__

VERSION = 2
TRACK = 0.40            # the cart must stay within +-TRACK [m] (true position)
SOFT_LIMIT = 0.28       # an open-loop segment hands over to the position loop beyond this [m]
FALLEN = 0.5236         # |theta| from upright beyond which a balancing run has failed [rad]
SUBSTEP = 1e-4          # largest internal step [s]
WINDOW = 1.0            # multiple-shooting window of the contributions [s]
MAX_ATTEMPTS = 12
NEAREST_SCALE = (0.5, 2.0)   # the mass scales searched for the model one correction leaves (one_correction)

LIBRARY = ("deadzone", "saturation", "delay", "cogging", "asymmetry", "offset", "sensor_bias",
           "drive_backlash")
OUTSIDE = ("spring", "friction_patch")
EFFECT_WEIGHTS = {"none": 0.25, **{e: 0.6 / len(LIBRARY) for e in LIBRARY},
                  **{e: 0.15 / len(OUTSIDE) for e in OUTSIDE}}
EXPERIMENT_WEIGHTS = {"cart": 0.5, "hanging": 0.2, "loop": 0.3}
TWO_EFFECTS_SHARE = 0.08     # of the cases with an effect
PLANT_ERROR_SHARE = 0.12

# parameter vector p
(P_M, P_MP, P_L, P_G, P_AL, P_BE, P_FC, P_FS, P_EPS, P_VS, P_ASYM, P_CA, P_CP, P_CPH,
 P_GAP, P_MB, P_KB, P_CB, P_F0, P_KS, P_FPRE, P_PLO, P_PHI, P_PF, P_PW) = range(25)
NP = 25
# input-effect vector: deadzone [V], saturation u_max [V] (0 = none), delay [s]
I_DZ, I_UMAX, I_DELAY = range(3)
# controller vector c
(C_K0, C_K1, C_K2, C_K3, C_EST, C_FC, C_ABA, C_ABB, C_VLIM, C_XRES, C_THRES, C_BIAS, C_ZREF,
 C_SOFT, C_SOFTGAIN, C_FALL, C_TRACK) = range(17)
NC = 17


# ============================================================================ dynamics
@_jit
def _sstep(z):
    z = min(max(z, 0.0), 1.0)
    return z * z * (3.0 - 2.0 * z)


@_jit
def _patch(x, p):
    """Fraction 0..1 of the friction patch at x."""
    if p[P_PF] == 0.0:
        return 0.0
    return _sstep((x - p[P_PLO]) / p[P_PW]) * _sstep((p[P_PHI] - x) / p[P_PW])


@_jit
def _contact(d, dv, p):
    half = 0.5 * p[P_GAP]
    if d > half:
        return max(p[P_KB] * (d - half) + p[P_CB] * dv, 0.0)
    if d < -half:
        return min(p[P_KB] * (d + half) + p[P_CB] * dv, 0.0)
    return 0.0


@_jit
def _net(y, th, w, u, p):
    """Force on the cart other than friction, taken at x'' = 0 [N]."""
    if p[P_MB] > 0.0:
        drive = _contact(y[4] - y[0], y[5] - y[1], p)
    else:
        drive = p[P_AL] * u - p[P_BE] * y[1]
    f = drive + p[P_F0] + p[P_FPRE] - p[P_KS] * y[0]
    if p[P_CA] != 0.0:
        f += p[P_CA] * math.sin(2.0 * math.pi * y[0] / p[P_CP] + p[P_CPH])
    m = p[P_MP]
    if m > 0.0:
        s, c = math.sin(th), math.cos(th)
        f += m * p[P_L] * s * w * w - 0.75 * m * p[P_G] * s * c
    return f


@_jit
def _pend(t, y, pr):
    """Pendulum (theta, rate) at t: the state's, or the prescribed cubic Hermite."""
    if pr[0] == 0.0:
        return y[2], y[3]
    h = pr[2]
    s = (t - pr[1]) / h
    s2, s3 = s * s, s * s * s
    th = ((2 * s3 - 3 * s2 + 1) * pr[3] + (s3 - 2 * s2 + s) * h * pr[4]
          + (-2 * s3 + 3 * s2) * pr[5] + (s3 - s2) * h * pr[6])
    w = ((6 * s2 - 6 * s) * pr[3] + (3 * s2 - 4 * s + 1) * h * pr[4]
         + (-6 * s2 + 6 * s) * pr[5] + (3 * s2 - 2 * s) * h * pr[6]) / h
    return th, w


@_jit
def _deriv(t, y, u, sgn, stuck, p, pr, dy):
    """y = (x, x', th, th', xb, xb'); sgn the frozen direction of sliding."""
    m = p[P_MP]
    th, w = _pend(t, y, pr)
    c = math.cos(th)
    acc = 0.0
    if not stuck:
        fc = p[P_FC] * (1.0 + p[P_PF] * _patch(y[0], p))
        lev = (1.0 + p[P_ASYM] * sgn) * (fc + (p[P_FS] - p[P_FC]) * math.exp(-(y[1] / p[P_VS]) ** 2))
        acc = (_net(y, th, w, u, p) - lev * sgn - p[P_EPS] * y[1]) / (p[P_M] + m - 0.75 * m * c * c)
    dy[0] = y[1]
    dy[1] = acc
    dy[2] = w
    dy[3] = 0.75 * (p[P_G] * math.sin(th) - c * acc) / p[P_L] if (m > 0.0 and pr[0] == 0.0) else 0.0
    dy[4] = y[5]
    dy[5] = 0.0
    if p[P_MB] > 0.0:
        dy[5] = (p[P_AL] * u - p[P_BE] * y[5] - _contact(y[4] - y[0], y[5] - y[1], p)) / p[P_MB]


@_jit
def _rk4(t, y, h, u, sgn, stuck, p, pr, wk, out):
    k1, k2, k3, k4, tmp = wk[0], wk[1], wk[2], wk[3], wk[4]
    _deriv(t, y, u, sgn, stuck, p, pr, k1)
    for i in range(6):
        tmp[i] = y[i] + 0.5 * h * k1[i]
    _deriv(t + 0.5 * h, tmp, u, sgn, stuck, p, pr, k2)
    for i in range(6):
        tmp[i] = y[i] + 0.5 * h * k2[i]
    _deriv(t + 0.5 * h, tmp, u, sgn, stuck, p, pr, k3)
    for i in range(6):
        tmp[i] = y[i] + h * k3[i]
    _deriv(t + h, tmp, u, sgn, stuck, p, pr, k4)
    for i in range(6):
        out[i] = y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])


@_jit
def _to_rest(t, y, rem, u, sgn, p, pr, wk):
    """Advance y to where x' reaches 0 within (0, rem] (Illinois regula falsi); return the time
    taken. On entry wk[5] holds the state after rem, where sgn x' <= 0."""
    lo, flo = 0.0, sgn * y[1]
    hi, fhi = rem, sgn * wk[5, 1]
    if flo <= 0.0:
        y[1] = 0.0
        return 0.0
    tau, side = hi, 0
    for _ in range(60):
        tau = lo + (hi - lo) * flo / (flo - fhi)
        _rk4(t, y, tau, u, sgn, False, p, pr, wk, wk[6])
        f = sgn * wk[6, 1]
        if abs(f) < 1e-11 or hi - lo < 1e-13:
            break
        if f > 0.0:
            lo, flo = tau, f
            if side == 1:
                fhi *= 0.5
            side = 1
        else:
            hi, fhi = tau, f
            if side == -1:
                flo *= 0.5
            side = -1
    y[:] = wk[6]
    y[1] = 0.0
    return tau


@_jit
def _substep(t, y, h, u, st, p, pr, wk):
    """Advance y by h from t; st = (stuck, direction) updated."""
    rem = h
    tt = t
    for _ in range(8):
        if st[0] == 1:
            th, w = _pend(tt, y, pr)
            n = _net(y, th, w, u, p)
            fs = p[P_FS] + p[P_FC] * p[P_PF] * _patch(y[0], p)
            if n > fs * (1.0 + p[P_ASYM]):
                st[0], st[1] = 0, 1
            elif n < -fs * (1.0 - p[P_ASYM]):
                st[0], st[1] = 0, -1
            else:
                _rk4(tt, y, rem, u, 0, True, p, pr, wk, y)
                return
        _rk4(tt, y, rem, u, st[1], False, p, pr, wk, wk[5])
        if st[1] * wk[5, 1] > 0.0:
            y[:] = wk[5]
            return
        dt = _to_rest(tt, y, rem, u, st[1], p, pr, wk)
        rem -= dt
        tt += dt
        st[0] = 1
        if rem <= 0.0:
            return
    _rk4(tt, y, rem, u, st[1], st[0] == 1, p, pr, wk, y)


@_jit
def _motor(v, inp):
    """Deadzone then amplifier clip of the (delayed) command [V]."""
    dz = inp[I_DZ]
    u = 0.0 if abs(v) <= dz else v - math.copysign(dz, v)
    if inp[I_UMAX] > 0.0:
        u = min(max(u, -inp[I_UMAX]), inp[I_UMAX])
    return u


@_jit
def _interval(t0, t1, y, st, volt, tt, jd, inp, p, pr, hmax, wk):
    """Advance y over [t0, t1] with the delayed, held command; jd = index of the command in
    force at t0 (-1: none yet). Returns jd at t1. The command V_j reaches the motor at t_j + d."""
    d = inp[I_DELAY]
    k = tt.size
    a = t0
    while True:
        nxt = t1
        if jd + 1 < k and tt[jd + 1] + d < t1 - 1e-12:
            nxt = max(tt[jd + 1] + d, a)
        u = _motor(volt[jd], inp) if jd >= 0 else _motor(0.0, inp)
        span = nxt - a
        if span > 0.0:
            ns = int(math.ceil(span / hmax - 1e-9))
            h = span / ns
            for i in range(ns):
                _substep(a + i * h, y, h, u, st, p, pr, wk)
        a = nxt
        if nxt >= t1:
            return jd
        jd += 1


@_jit
def _experiment(t, frozen, mode, seg, sched, target, gain, p, c, inp, y0, hmax):
    """Sampled experiment. At sample k: read the encoders (frozen: repeat the last readings),
    estimate velocities, compute the command V_k, then advance to t[k+1] with V delayed/held.

    mode 0: V = sched (open loop; beyond SOFT_LIMIT the rest of the segment is the position loop
    towards 0); mode 1: V = sched + gain (target - x_enc); mode 2: V = K . (x_enc - target,
    th_enc, vx, vth) + sched. Clipped at +-c[C_VLIM] except mode 0 within the limit.
    Velocity estimates: c[C_EST] 0 filtered difference at c[C_FC] Hz, 1 plain difference,
    2 alpha-beta observer (c[C_ABA], c[C_ABB]).
    Returns readings (x_enc, th_enc in the encoder frame), V, true states, stick states, rows
    recorded and an end code (0 whole run, 1 fallen, 2 track)."""
    n = t.size
    xe, the, volt = np.zeros(n), np.zeros(n), np.zeros(n)
    Y = np.zeros((n, 6))
    ST = np.zeros((n, 2), dtype=np.int64)
    y = y0.copy()
    st = np.array([1, 1])
    wk = np.zeros((7, 6))
    pr = np.zeros(7)
    xres, thres, zref = c[C_XRES], c[C_THRES], c[C_ZREF]
    vx = vth = 0.0
    xh = thh = 0.0
    latch, lastseg = 0, -1
    jd = -1
    est = int(c[C_EST])
    for k in range(n):
        if frozen[k] and k > 0:
            xe[k], the[k] = xe[k - 1], the[k - 1]
        else:
            xe[k] = xres * np.round(y[0] / xres) + 0.0
            the[k] = thres * np.round((y[2] + c[C_BIAS] - zref) / thres) + 0.0
        thc = the[k] + zref
        thc = thc - 2.0 * math.pi * np.round(thc / (2.0 * math.pi))
        if k == 0:
            xh, thh = xe[0], thc
        else:
            dt = t[k] - t[k - 1]
            thp = the[k - 1] + zref
            thp = thp - 2.0 * math.pi * np.round(thp / (2.0 * math.pi))
            if est == 0:
                a = 1.0 - math.exp(-2.0 * math.pi * c[C_FC] * dt)
                vx += a * ((xe[k] - xe[k - 1]) / dt - vx)
                vth += a * ((thc - thp) / dt - vth)
            elif est == 1:
                vx = (xe[k] - xe[k - 1]) / dt
                vth = (thc - thp) / dt
            else:
                xp, tp = xh + dt * vx, thh + dt * vth
                rx, rt = xe[k] - xp, thc - tp
                xh, thh = xp + c[C_ABA] * rx, tp + c[C_ABA] * rt
                vx += c[C_ABB] * rx / dt
                vth += c[C_ABB] * rt / dt
        if seg[k] != lastseg:
            latch, lastseg = 0, seg[k]
        if mode[k] == 0 and abs(xe[k]) > c[C_SOFT]:
            latch = 1
        if mode[k] == 0 and latch == 0:
            v = sched[k]
        elif mode[k] == 0:
            v = min(max(c[C_SOFTGAIN] * (0.0 - xe[k]), -c[C_VLIM]), c[C_VLIM])
        elif mode[k] == 1:
            v = min(max(sched[k] + gain[k] * (target[k] - xe[k]), -c[C_VLIM]), c[C_VLIM])
        else:
            v = (c[C_K0] * (xe[k] - target[k]) + c[C_K1] * thc + c[C_K2] * vx + c[C_K3] * vth
                 + sched[k])
            v = min(max(v, -c[C_VLIM]), c[C_VLIM])
        volt[k] = v + 0.0
        Y[k] = y
        ST[k, 0], ST[k, 1] = st[0], st[1]
        thu = y[2] - 2.0 * math.pi * np.round(y[2] / (2.0 * math.pi))
        if c[C_FALL] > 0.0 and abs(thu) > c[C_FALL]:
            return xe, the, volt, Y, ST, k + 1, 1
        if abs(y[0]) > c[C_TRACK]:
            return xe, the, volt, Y, ST, k + 1, 2
        if k + 1 < n:
            jd = _interval(t[k], t[k + 1], y, st, volt, t, jd, inp, p, pr, hmax, wk)
    return xe, the, volt, Y, ST, n, 0


@_jit
def _replay(t, volt, Y, ST, starts, p, inp, presc, hmax):
    """Multiple shooting: from the true state at each window start, replay the recorded
    command; returns the simulated cart position at every sample (and the true angle)."""
    n = t.size
    xs = np.zeros(n)
    wk = np.zeros((7, 6))
    pr = np.zeros(7)
    st = np.array([1, 1])
    d = inp[I_DELAY]
    for w in range(starts.size):
        k0 = starts[w]
        k1 = starts[w + 1] if w + 1 < starts.size else n
        y = Y[k0].copy()
        st[0], st[1] = ST[k0, 0], ST[k0, 1]
        jd = -1
        while jd + 1 <= k0 and t[jd + 1] + d <= t[k0] + 1e-12:
            jd += 1
        for k in range(k0, k1):
            xs[k] = y[0]
            if k + 1 < n:
                if presc:
                    pr[0], pr[1], pr[2] = 1.0, t[k], t[k + 1] - t[k]
                    pr[3], pr[4], pr[5], pr[6] = Y[k, 2], Y[k, 3], Y[k + 1, 2], Y[k + 1, 3]
                jd = _interval(t[k], t[k + 1], y, st, volt, t, jd, inp, p, pr, hmax, wk)
                if presc:
                    y[2], y[3] = Y[k + 1, 2], Y[k + 1, 3]
    return xs


# ============================================================================ drawing
def _logu(rng, lo, hi):
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def _pick(rng, weights):
    names = list(weights)
    w = np.array([weights[k] for k in names], float)
    return names[int(rng.choice(len(names), p=w / w.sum()))]


def _draw_rig(rng, pendulum):
    M = _logu(rng, 0.2, 2.0)
    m = float(np.clip(M * rng.uniform(0.08, 0.4), 0.03, 0.6))
    l = rng.uniform(0.1, 0.45)
    g = 9.81
    alpha = rng.uniform(0.5, 3.0)
    beta = rng.uniform(1.0, 12.0)
    FN = (M + (m if pendulum else 0.0)) * g
    Fc = float(np.clip(_logu(rng, 0.01, 0.15) * FN, 0.05, 2.0))
    Fs = Fc * (1.0 + rng.uniform(0.05, 1.2))
    eps = _logu(rng, 0.2, 5.0)
    v_s = _logu(rng, 0.01, 0.2)
    x_res = _logu(rng, 1e-5, 1e-4)
    theta_counts = int(rng.choice([1024, 2048, 4096]))
    return dict(M=M, m=m, l=l, g=g, alpha=alpha, beta=beta, Fc=Fc, Fs=Fs, Fs_excess=Fs - Fc,
                eps=eps, v_s=v_s, gamma=2.0, F_N=FN, mu_c=Fc / FN, mu_s=Fs / FN,
                x_res=x_res, theta_counts_per_turn=theta_counts,
                theta_res=2 * math.pi / theta_counts)


def _draw_effect(rng, name, rig, experiment):
    """Parameters of one effect, its size log-uniform from invisible to obvious."""
    Fc, Vb = rig["Fc"], rig["Fs"] / rig["alpha"]
    sgn = 1.0 if rng.uniform() < 0.5 else -1.0
    if name == "deadzone":
        return dict(dz_V=Vb * _logu(rng, 3e-4, 0.6))
    if name == "saturation":
        return dict(u_max_fraction=_logu(rng, 0.4, 1.2),
                    note="u_max = u_max_fraction x the 99.9th percentile of |V| of the run without it")
    if name == "delay":
        return dict(delay_s=_logu(rng, 5e-5, 0.03))
    if name == "cogging":
        return dict(amplitude_N=Fc * _logu(rng, 2e-4, 1.0), period_m=rng.uniform(0.002, 0.02),
                    phase_rad=rng.uniform(0, 2 * math.pi))
    if name == "asymmetry":
        return dict(a=sgn * _logu(rng, 2e-4, 0.5))
    if name == "offset":
        return dict(F0_N=sgn * Fc * _logu(rng, 2e-4, 1.0))
    if name == "sensor_bias":
        return dict(theta_bias_rad=sgn * rig["theta_res"] * _logu(rng, 0.05, 20.0))
    if name == "drive_backlash":
        mb = rig["M"] * rng.uniform(0.1, 0.5)
        mu = mb * rig["M"] / (mb + rig["M"])
        f = rng.uniform(50.0, 200.0)
        k = mu * (2 * math.pi * f) ** 2
        zeta = rng.uniform(0.05, 0.3)
        return dict(gap_m=_logu(rng, 5e-6, 3e-3), motor_mass_kg=mb, k_N_per_m=k,
                    c_N_s_per_m=2 * zeta * math.sqrt(k * mu), contact_frequency_Hz=f, damping_ratio=zeta)
    if name == "spring":
        k = Fc * _logu(rng, 2e-4, 1.5) / 0.1
        pre = sgn * rng.uniform(0.0, 0.5) * k * 0.1 if rng.uniform() < 0.5 else 0.0
        return dict(k_N_per_m=k, preload_N=pre)
    if name == "friction_patch":
        length = rng.uniform(0.03, 0.10)
        centre = rng.uniform(-0.15, 0.15)
        return dict(fraction=_logu(rng, 2e-3, 2.0), x_lo_m=centre - length / 2,
                    x_hi_m=centre + length / 2, edge_m=0.002)
    raise ValueError(name)


def _cart_plan(rig, duration, rng, pendulum):
    """Open-loop experiment (cart alone or pendulum hanging): segments (kind, start, length, q)."""
    Vb = rig["Fs"] / rig["alpha"]
    damp = rig["beta"] + rig["eps"]
    vlim = 10.0
    KF = max(40.0, 1.5 * rig["Fs"] / 0.01)
    gain = KF / rig["alpha"]
    plan = []

    def add(kind, length, **q):
        start = plan[-1][1] + plan[-1][2] if plan else 0.0
        plan.append((kind, start, float(length), q))

    def move(target):
        add("reposition", rng.uniform(1.5, 2.5), target=float(target), gain_V_per_m=gain, sched_V=0.0)
        add("rest", rng.uniform(0.3, 1.0))

    add("rest", rng.uniform(0.3, 1.0))
    blocks = ["ramps", "steps", "pulses", "multisine", "steps", "ramps"]
    rng.shuffle(blocks)
    bi = 0
    while (plan[-1][1] + plan[-1][2]) < duration - 12.0:
        b = blocks[bi % len(blocks)]
        bi += 1
        if b == "ramps":
            for sign in (1, -1):
                move(-0.2 * sign)
                rate = Vb / rng.uniform(1.0, 3.0)
                add("ramp", min(6.0, 1.6 * Vb / rate + 0.5), rate_V_per_s=sign * rate)
                add("rest", rng.uniform(0.8, 2.0))
        elif b == "steps":
            for volts in np.sort(Vb * rng.uniform(1.2, 4.0, 2)):
                volts = min(float(volts), vlim)
                for sign in (1, -1):
                    move(-0.2 * sign)
                    vss = max((rig["alpha"] * volts - rig["Fc"]) / damp, 0.02)
                    add("step", round(min(3.0, 0.3 / vss), 3), V=sign * volts)
                    add("rest", rng.uniform(1.0, 2.0))
        elif b == "pulses":
            move(0.0)
            add("pulses", rng.uniform(4.0, 8.0), V=min(vlim, Vb * rng.uniform(1.5, 4.0)),
                width_s=rng.uniform(0.05, 0.15), period_s=rng.uniform(0.8, 1.5))
        else:
            move(0.0)
            add("multisine", rng.uniform(8.0, 15.0), **_multisine(rng, Vb * rng.uniform(0.8, 2.5)),
                target=0.0, gain_V_per_m=gain * rng.uniform(0.2, 0.5))
    move(0.0)
    used = plan[-1][1] + plan[-1][2]
    add("multisine", max(8.0, duration - used), **_multisine(rng, Vb * rng.uniform(0.8, 2.5)),
        target=0.0, gain_V_per_m=gain * rng.uniform(0.2, 0.5))
    return plan, vlim, KF / rig["alpha"]


def _multisine(rng, amplitude):
    freqs = np.unique(np.round(np.geomspace(0.1, 5.0, int(rng.integers(8, 16))), 2))
    phases = rng.uniform(0.0, 2 * math.pi, freqs.size)
    tt = np.arange(0.0, 10.0, 1e-3)
    peak = np.abs(np.sin(2 * math.pi * np.outer(tt, freqs) + phases).sum(axis=1)).max()
    return dict(freqs_Hz=freqs.tolist(), phases_rad=phases.tolist(), amplitude_V=float(amplitude / peak),
                offset_V=float(rng.uniform(-0.1, 0.1) * amplitude))


def _plan_signals(plan, t):
    n = t.size
    mode, seg = np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
    sched, target, gain = np.zeros(n), np.zeros(n), np.zeros(n)
    starts = np.array([s[1] for s in plan])
    idx = np.searchsorted(starts, t, side="right") - 1
    seg[:] = idx
    for i, (kind, start, length, q) in enumerate(plan):
        sel = idx == i
        tau = t[sel] - start
        if kind in ("reposition", "multisine"):
            mode[sel], target[sel], gain[sel] = 1, q["target"], q["gain_V_per_m"]
        if kind == "ramp":
            sched[sel] = q["rate_V_per_s"] * tau
        elif kind == "step":
            sched[sel] = np.where(tau < length, q["V"], 0.0)
        elif kind == "pulses":
            ph = np.mod(tau, q["period_s"])
            half = 0.5 * q["period_s"]
            sched[sel] = q["V"] * ((ph < q["width_s"]) * 1.0 - ((ph >= half) & (ph < half + q["width_s"])))
        elif kind == "multisine":
            arg = 2 * math.pi * np.outer(tau, q["freqs_Hz"]) + np.array(q["phases_rad"])
            sched[sel] = q["offset_V"] + q["amplitude_V"] * np.sin(arg).sum(axis=1)
    return mode, seg, sched, target, gain


def _stamps(rng, Ts, duration, timing):
    """Sample instants (true; jittered ones included), frozen flags, metadata."""
    n = int(round(duration / Ts)) + 1
    frozen = np.zeros(n, dtype=np.bool_)
    ticks = np.arange(n, dtype=float)
    meta = {"kind": timing["kind"]}
    if timing["kind"] in ("overrun", "jitter_overrun"):
        events = max(1, int(duration * timing["overruns_per_s"]))
        jumps = np.sort(rng.choice(np.arange(20, n - 20), size=min(events, n // 40), replace=False))
        steps = np.ones(n - 1)
        steps[jumps - 1] = rng.integers(2, 4, jumps.size)
        ticks = np.concatenate([[0.0], np.cumsum(steps)])
        for j, f in zip(jumps, rng.integers(1, 4, jumps.size)):
            frozen[j + 1:j + 1 + f] = True
        meta.update(jump_rows=jumps.tolist(), overruns=int(jumps.size))
    t = ticks * Ts
    if timing["kind"] in ("jitter", "jitter_overrun"):
        t = t + rng.uniform(-1, 1, t.size) * timing["jitter_fraction"] * Ts
        t[0] = 0.0
        meta["jitter_max_s"] = timing["jitter_fraction"] * Ts
    keep = t <= duration + 1e-9
    return t[keep], frozen[keep], meta


def draw_case(seed, index, attempt=0):
    """The spec of case (seed, index): every drawn value, JSON-serialisable."""
    top = np.random.default_rng([int(seed), int(index)])       # kept over redraws
    rng = np.random.default_rng([int(seed), int(index), int(attempt)])
    effect = _pick(top, EFFECT_WEIGHTS)
    effects = [] if effect == "none" else [effect]
    if effects and top.uniform() < TWO_EFFECTS_SHARE:
        second = _pick(top, {k: v for k, v in EFFECT_WEIGHTS.items() if k not in ("none", effect)})
        effects.append(second)
    exp_w = dict(EXPERIMENT_WEIGHTS)
    if "sensor_bias" in effects:
        exp_w.pop("cart")
    experiment = _pick(top, exp_w)
    theta_u = top.uniform()
    pendulum = experiment != "cart"
    rig = _draw_rig(rng, pendulum)
    Ts = float(rng.choice([0.001, 0.002, 0.004, 0.005, 0.01]) if rng.uniform() < 0.6
               else round(rng.uniform(0.001, 0.01), 4))
    if experiment == "loop":
        duration = float(round(rng.uniform(30.0, 60.0), 1))
    else:
        duration = float(round(rng.uniform(45.0, 120.0), 1))
    tk = _pick(rng, {"regular": 0.4, "jitter": 0.2, "overrun": 0.25, "jitter_overrun": 0.15})
    timing = {"kind": tk, "jitter_fraction": float(rng.uniform(0.05, 0.35)),
              "overruns_per_s": float(_logu(rng, 0.1, 1.0))}
    spec = dict(version=VERSION, seed=int(seed), index=int(index), attempt=int(attempt),
                experiment=experiment, pendulum_attached=pendulum, rig=rig, Ts=Ts, duration=duration,
                timing=timing, effects={e: _draw_effect(rng, e, rig, experiment) for e in effects})
    if experiment == "cart":
        spec["theta_column"] = "zeros" if theta_u < 0.3 else "none"
    elif experiment == "hanging":
        spec["theta_column"] = ["from_hanging", "from_upright", "from_upright_wrapped"][int(theta_u * 3)]
    else:
        spec["theta_column"] = "from_upright" if theta_u < 0.7 else "from_hanging_wrapped"
    if experiment == "loop":
        Q = [_logu(rng, 1000, 10000), _logu(rng, 1000, 10000), _logu(rng, 5, 50), _logu(rng, 5, 50)]
        est = str(rng.choice(["filtered", "difference", "alpha_beta"], p=[0.5, 0.2, 0.3]))
        aba = float(rng.uniform(0.3, 0.8))
        exc = str(rng.choice(["none", "setpoint", "dither"], p=[0.4, 0.4, 0.2]))
        spec["controller"] = dict(
            Q=Q, r=1.0, eps_design=rig["eps"] * float(rng.uniform(0.5, 1.5)),
            estimator=est, filter_Hz=float(rng.uniform(10.0, 50.0)), alpha_beta=[aba, aba * aba / (2 - aba)],
            voltage_limit_V=float(rng.uniform(5.0, 12.0)),
            theta0_rad=float(rng.choice([-1, 1]) * rng.uniform(0.01, 0.05)),
            excitation=exc, setpoint_m=float(rng.uniform(0.02, 0.08)), setpoint_period_s=float(rng.uniform(4.0, 10.0)),
            dither=_multisine(rng, rig["Fs"] / rig["alpha"] * float(rng.uniform(0.2, 0.8))))
    else:
        spec["x0_m"] = float(rng.uniform(-0.05, 0.05))
        spec["plan_seed"] = int(rng.integers(0, 2 ** 31))
    if rng.uniform() < PLANT_ERROR_SHARE:
        names = ["M", "alpha", "beta"] + (["m", "l"] if pendulum else [])
        name = str(rng.choice(names))
        factor = float(1.0 + rng.choice([-1, 1]) * rng.uniform(0.1, 0.4))
        spec["plant_error"] = dict(name=name, factor=factor, true=rig[name], declared=rig[name] * factor)
    return spec


# ============================================================================ simulation
def _pvec(spec, effects, rig=None):
    rig = rig or spec["rig"]
    p = np.zeros(NP)
    p[[P_M, P_MP, P_L, P_G, P_AL, P_BE, P_FC, P_FS, P_EPS, P_VS]] = (
        rig["M"], rig["m"] if spec["pendulum_attached"] else 0.0, rig["l"], rig["g"], rig["alpha"],
        rig["beta"], rig["Fc"], rig["Fs"], rig["eps"], rig["v_s"])
    p[P_CP] = 1.0
    p[P_PW] = 1.0
    inp = np.zeros(3)
    for name, q in effects.items():
        if name == "deadzone":
            inp[I_DZ] = q["dz_V"]
        elif name == "saturation":
            inp[I_UMAX] = q["u_max_V"]
        elif name == "delay":
            inp[I_DELAY] = q["delay_s"]
        elif name == "cogging":
            p[[P_CA, P_CP, P_CPH]] = q["amplitude_N"], q["period_m"], q["phase_rad"]
        elif name == "asymmetry":
            p[P_ASYM] = q["a"]
        elif name == "offset":
            p[P_F0] = q["F0_N"]
        elif name == "drive_backlash":
            p[[P_GAP, P_MB, P_KB, P_CB]] = q["gap_m"], q["motor_mass_kg"], q["k_N_per_m"], q["c_N_s_per_m"]
        elif name == "spring":
            p[P_KS], p[P_FPRE] = q["k_N_per_m"], q["preload_N"]
        elif name == "friction_patch":
            p[[P_PF, P_PLO, P_PHI, P_PW]] = q["fraction"], q["x_lo_m"], q["x_hi_m"], q["edge_m"]
        elif name == "sensor_bias":
            pass
        else:
            raise ValueError(name)
    return p, inp


def _hmax(spec):
    q = spec["effects"].get("drive_backlash")
    if q is None:
        return SUBSTEP
    return min(SUBSTEP, 1.0 / (40.0 * q["contact_frequency_Hz"]) * 1.0)


def _lqr(spec):
    rig, c = spec["rig"], spec["controller"]
    design = dict(rig, eps=c["eps_design"])
    return rigsim.lqr_gain(design, eps=c["eps_design"], Q=tuple(c["Q"]), r=c["r"])


def _signals(spec, t):
    """Per-sample mode, segment, schedule, target, gain; controller vector; plan metadata."""
    rig = spec["rig"]
    c = np.zeros(NC)
    c[C_XRES], c[C_THRES], c[C_TRACK] = rig["x_res"], rig["theta_res"], TRACK
    c[C_BIAS] = spec["effects"].get("sensor_bias", {}).get("theta_bias_rad", 0.0)
    col = spec["theta_column"]
    c[C_ZREF] = math.pi if col.startswith("from_hanging") else 0.0
    meta = {}
    if spec["experiment"] == "loop":
        ctl = spec["controller"]
        K = _lqr(spec)
        c[C_K0:C_K3 + 1] = K
        c[C_EST] = {"filtered": 0, "difference": 1, "alpha_beta": 2}[ctl["estimator"]]
        c[C_FC] = ctl["filter_Hz"]
        c[C_ABA], c[C_ABB] = ctl["alpha_beta"]
        c[C_VLIM] = ctl["voltage_limit_V"]
        c[C_FALL] = FALLEN
        n = t.size
        mode = np.full(n, 2, dtype=np.int64)
        seg = np.zeros(n, dtype=np.int64)
        sched, target, gain = np.zeros(n), np.zeros(n), np.zeros(n)
        if ctl["excitation"] == "setpoint":
            target[:] = np.where(np.mod(t, ctl["setpoint_period_s"]) < 0.5 * ctl["setpoint_period_s"],
                                 ctl["setpoint_m"], -ctl["setpoint_m"])
            target[t < 3.0] = 0.0
        elif ctl["excitation"] == "dither":
            q = ctl["dither"]
            arg = 2 * math.pi * np.outer(t, q["freqs_Hz"]) + np.array(q["phases_rad"])
            sched[:] = q["amplitude_V"] * np.sin(arg).sum(axis=1) * (t >= 3.0)
        meta["K"] = [float(k) for k in K]
        return (mode, seg, sched, target, gain), c, meta
    rng = np.random.default_rng(spec["plan_seed"])
    plan, vlim, softgain = _cart_plan(rig, spec["duration"], rng, spec["pendulum_attached"])
    c[C_VLIM], c[C_SOFT], c[C_SOFTGAIN] = vlim, SOFT_LIMIT, softgain
    meta["segments"] = [dict(kind=k, t0=round(s, 6), t1=round(s + d, 6), **q) for k, s, d, q in plan]
    return _plan_signals(plan, t), c, meta


def _y0(spec):
    y0 = np.zeros(6)
    if spec["experiment"] == "loop":
        y0[2] = spec["controller"]["theta0_rad"]
    else:
        y0[0] = y0[4] = spec["x0_m"]
        if spec["pendulum_attached"]:
            y0[2] = math.pi
    return y0


def _run(spec, effects):
    rng = np.random.default_rng([spec["seed"], spec["index"], spec["attempt"], 1])
    t, frozen, tmeta = _stamps(rng, spec["Ts"], spec["duration"], spec["timing"])
    (mode, seg, sched, target, gain), c, meta = _signals(spec, t)
    p, inp = _pvec(spec, effects)
    out = _experiment(t, frozen, mode, seg, sched, target, gain, p, c, inp, _y0(spec), _hmax(spec))
    xe, the, volt, Y, ST, rows, end = out
    return dict(t=t[:rows], frozen=frozen[:rows], x=xe[:rows], theta_enc=the[:rows], voltage=volt[:rows],
                Y=Y[:rows], ST=ST[:rows], end=("duration", "fallen", "track")[end], timing=tmeta,
                meta=meta, c=c)


def simulate(spec):
    """Run the experiment of a spec with its effects. Saturation's u_max is set from a run
    without it (the 99.9th percentile of |V| times its drawn fraction) before the real run."""
    effects = {k: dict(v) for k, v in spec["effects"].items()}
    if "saturation" in effects:
        pre = _run(spec, {k: v for k, v in effects.items() if k != "saturation"})
        ref = float(np.percentile(np.abs(pre["voltage"]), 99.9))
        effects["saturation"]["u_max_V"] = max(ref * effects["saturation"]["u_max_fraction"], 1e-3)
    data = _run(spec, effects)
    data["effects"] = effects
    return data


def _theta_out(spec, data):
    col = spec["theta_column"]
    if col == "none":
        return None
    if col == "zeros":
        return np.zeros(data["t"].size)
    th = data["theta_enc"]                     # encoder frame: zero hanging or upright
    if col.endswith("wrapped"):
        th = rigsim._wrap(th)
        res = spec["rig"]["theta_res"]
        th = res * np.round(th / res) + 0.0
    return th


def _window_starts(t):
    edges = np.arange(0.0, t[-1], WINDOW)
    return np.unique(np.searchsorted(t, edges - 1e-12)).astype(np.int64)


def contributions(spec, data):
    """Each effect's own contribution (and the plant error's): RMS counts, see the docstring."""
    t, volt, Y, ST = data["t"], data["voltage"], data["Y"], data["ST"]
    starts = _window_starts(t)
    presc = bool(spec["pendulum_attached"])
    hmax = _hmax(spec)
    rig = spec["rig"]
    full = data["effects"]
    p, inp = _pvec(spec, full)
    x_with = _replay(t, volt, Y, ST, starts, p, inp, presc, hmax)
    val = t >= 0.6 * t[-1]
    self_err = (x_with - Y[:, 0]) / rig["x_res"]
    out = {"replay_self_error_counts_rms": float(np.sqrt(np.mean(self_err ** 2)))}

    def rms(d):
        return float(np.sqrt(np.mean(d ** 2))), float(np.sqrt(np.mean(d[val] ** 2))), float(np.abs(d).max())

    for name in full:
        if name == "sensor_bias":
            d = np.full(t.size, full[name]["theta_bias_rad"] / rig["theta_res"])
            unit = "angle counts"
        else:
            others = {k: v for k, v in full.items() if k != name}
            if name == "drive_backlash":
                # without the play the drive is direct: start the replays from the cart's state
                p2, inp2 = _pvec(spec, others)
                Y2 = Y.copy()
                Y2[:, 4:6] = Y[:, 0:2]
                d = (x_with - _replay(t, volt, Y2, ST, starts, p2, inp2, presc, hmax)) / rig["x_res"]
            else:
                p2, inp2 = _pvec(spec, others)
                d = (x_with - _replay(t, volt, Y, ST, starts, p2, inp2, presc, hmax)) / rig["x_res"]
            unit = "cart counts"
        a, b, mx = rms(d)
        out[name] = dict(contribution_counts_rms=a, contribution_counts_rms_validation=b,
                         contribution_counts_max=mx, unit=unit)
        if name == "deadzone":
            # the part a friction level cannot take over: while the cart moves the way it is driven, a
            # deadzone dz is a Coulomb (and static) level higher by alpha dz
            shift = rig["alpha"] * full[name]["dz_V"]
            level = dict(rig, Fc=rig["Fc"] + shift, Fs=rig["Fs"] + shift)
            p2, inp2 = _pvec(spec, others, level)
            d = (x_with - _replay(t, volt, Y, ST, starts, p2, inp2, presc, hmax)) / rig["x_res"]
            a, b, _ = rms(d)
            out[name].update(beyond_friction_counts_rms=a, beyond_friction_counts_rms_validation=b)
        if name == "drive_backlash":
            # the play's own part: the same drive with its motor side fixed to the cart (no play, a
            # rigid contact), i.e. a cart heavier by the motor side's mass
            q = full[name]
            rigid = dict(rig, M=rig["M"] + q["motor_mass_kg"])
            p2, inp2 = _pvec(spec, others, rigid)
            Y2 = Y.copy()
            Y2[:, 4:6] = Y[:, 0:2]
            d = (x_with - _replay(t, volt, Y2, ST, starts, p2, inp2, presc, hmax)) / rig["x_res"]
            a, b, _ = rms(d)
            out[name].update(play_contribution_counts_rms=a, play_contribution_counts_rms_validation=b)
            # and beyond a compliant contact without play: the same drive with its play closed (gap 0)
            closed = dict(full, drive_backlash=dict(q, gap_m=0.0))
            p2, inp2 = _pvec(spec, closed)
            d = (x_with - _replay(t, volt, Y, ST, starts, p2, inp2, presc, hmax)) / rig["x_res"]
            a, b, _ = rms(d)
            out[name].update(closed_contribution_counts_rms=a, closed_contribution_counts_rms_validation=b)
        if name == "spring":
            # its mean pull over the record, F_pre - k mean(x): a constant force (an offset); the spring without it
            q = full[name]
            pull = q["preload_N"] - q["k_N_per_m"] * float(np.mean(Y[:, 0]))
            p2, inp2 = _pvec(spec, dict(full, spring=dict(q, preload_N=q["preload_N"] - pull)))
            d = (x_with - _replay(t, volt, Y, ST, starts, p2, inp2, presc, hmax)) / rig["x_res"]
            a, b, _ = rms(d)
            out[name].update(mean_pull_N=pull, mean_pull_contribution_counts_rms=a,
                             mean_pull_contribution_counts_rms_validation=b)
    pe = spec.get("plant_error")
    if pe is not None:
        wrong = dict(rig, **{pe["name"]: pe["declared"]})
        p2, _ = _pvec(spec, full, wrong)
        d = (x_with - _replay(t, volt, Y, ST, starts, p2, inp, presc, hmax)) / rig["x_res"]
        a, b, mx = rms(d)
        out["plant_error"] = dict(contribution_counts_rms=a, contribution_counts_rms_validation=b,
                                  contribution_counts_max=mx, unit="cart counts")
        if pe["name"] == "m" and presc:
            out["plant_error"]["one_correction_counts_rms"] = one_correction(spec, data, x_with, starts, pe)
    return out


def one_correction(spec, data, x_with, starts, pe):
    """What one correction of the declared plant leaves of everything the library does not hold in a case with
    a wrong pendulum mass (m declared f times; the pair M and alpha by f is the rig): the replay with every
    drawn effect against the declared rig without the effects from outside the library, with one correction,
    the best of a bounded search (NEAREST_SCALE). ``alpha corrected``: every force scaled by one factor, which
    is both masses scaled by its inverse; ``M corrected``: the cart's mass alone. RMS cart counts."""
    t, volt, Y, ST = data["t"], data["voltage"], data["Y"], data["ST"]
    rig, hmax = spec["rig"], _hmax(spec)
    inside = {k: v for k, v in data["effects"].items() if k not in OUTSIDE}

    def left(s, scaled):
        p2, inp2 = _pvec(spec, inside, dict(rig, M=s * rig["M"], m=pe["declared"] * (s if scaled else 1.0)))
        d = (x_with - _replay(t, volt, Y, ST, starts, p2, inp2, True, hmax)) / rig["x_res"]
        return float(np.sqrt(np.mean(d ** 2)))
    return {name: float(minimize_scalar(left, bounds=NEAREST_SCALE, args=(scaled,), method="bounded",
                                        options={"xatol": 1e-4}).fun)
            for name, scaled in (("alpha corrected", True), ("M corrected", False))}


def _jsonable(o):
    if isinstance(o, dict):
        return {k: _jsonable(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_jsonable(v) for v in o]
    if isinstance(o, (np.floating,)):
        return float(o)
    if isinstance(o, (np.integer,)):
        return int(o)
    return o


def make_case(seed, index, duration=None):
    """(data, truth) of case (seed, index): redrawn (attempt + 1) while a run leaves the track,
    its pendulum falls or nothing moves. ``duration`` [s] overrides the drawn one (tests)."""
    reasons = []
    for attempt in range(MAX_ATTEMPTS):
        spec = draw_case(seed, index, attempt)
        if duration is not None:
            spec["duration"] = float(duration)
        data = simulate(spec)
        if data["end"] != "duration":
            reasons.append(f"attempt {attempt}: {data['end']} at t = {data['t'][-1]:.2f} s")
            continue
        if np.ptp(data["x"]) < 20 * spec["rig"]["x_res"]:
            reasons.append(f"attempt {attempt}: the cart hardly moved")
            continue
        break
    else:
        raise RuntimeError(f"case ({seed}, {index}): no attempt stayed on the track: {reasons}")
    contrib = contributions(spec, data)
    theta = _theta_out(spec, data)
    data["theta"] = theta
    rig = spec["rig"]
    declared = {k: rig[k] for k in ("M", "m", "l", "g", "alpha", "beta")}
    if "plant_error" in spec:
        declared[spec["plant_error"]["name"]] = spec["plant_error"]["declared"]
    effects = {}
    for name, q in data["effects"].items():
        effects[name] = dict(q, library=name in LIBRARY, **contrib[name])
    Y = data["Y"]
    truth = dict(
        spec=spec, case=case_name(index), seed=spec["seed"], index=spec["index"], attempt=spec["attempt"],
        redraws=reasons, experiment=spec["experiment"], pendulum_attached=spec["pendulum_attached"],
        effect_names=sorted(effects) or ["none"], effects=effects,
        contribution_counts_rms={k: v["contribution_counts_rms"] for k, v in effects.items()},
        plant_error=(dict(spec["plant_error"], **contrib["plant_error"]) if "plant_error" in spec else None),
        replay_self_error_counts_rms=contrib["replay_self_error_counts_rms"],
        constants={k: rig[k] for k in ("M", "m", "l", "g", "alpha", "beta")}, declared_plant=declared,
        friction={k: rig[k] for k in ("Fc", "Fs", "Fs_excess", "eps", "v_s", "gamma", "F_N", "mu_c", "mu_s")},
        encoder=dict(x_count_m=rig["x_res"], theta_count_rad=rig["theta_res"]),
        sample_period_s=spec["Ts"], timing=data["timing"], rows=int(data["t"].size),
        duration_s=float(data["t"][-1]), theta_column=spec["theta_column"],
        columns=["t", "x", "voltage"] + ([] if theta is None else ["theta"]),
        controller=(dict(spec["controller"], K=data["meta"]["K"]) if spec["experiment"] == "loop" else None),
        segments=data["meta"].get("segments"),
        voltage="command V as recorded (before delay, deadzone, saturation); held per sample",
        motion=dict(x_ptp_m=float(np.ptp(Y[:, 0])), max_abs_x_m=float(np.abs(Y[:, 0]).max()),
                    mean_x_m=float(np.mean(Y[:, 0])),
                    max_speed_mps=float(np.abs(Y[:, 1]).max()),
                    theta_ptp_rad=float(np.ptp(Y[:, 2])) if spec["pendulum_attached"] else None),
        generator=f"tests/independent/campaign.py v{VERSION}")
    return data, _jsonable(truth)


def case_name(index):
    return f"case{int(index):04d}"


def write_case(out_dir, seed, index, duration=None):
    """Write DIR/<case>/data.csv, plant.yaml, truth.json (the same bytes for the same (seed,
    index)); return the truth with ``generation_s`` (not written) added."""
    t0 = time.perf_counter()
    data, truth = make_case(seed, index, duration)
    d = Path(out_dir) / truth["case"]
    d.mkdir(parents=True, exist_ok=True)
    cols = [data["t"], data["x"], data["voltage"]] + ([] if data["theta"] is None else [data["theta"]])
    np.savetxt(d / "data.csv", np.column_stack(cols), fmt="%.12g", delimiter=",",
               header=",".join(truth["columns"]), comments="")
    dp = truth["declared_plant"]
    (d / "plant.yaml").write_text(
        "# declared plant (friction: none given, the paper's exponential law is the hypothesis)\n"
        "plant: {" + ", ".join(f"{k}: {dp[k]!r}" for k in ("M", "m", "l", "g", "alpha", "beta")) + "}\n")
    (d / "truth.json").write_text(json.dumps(truth, indent=1, sort_keys=True))
    return dict(truth, generation_s=round(time.perf_counter() - t0, 3))


def _summary(truth):
    return dict(case=truth["case"], index=truth["index"], experiment=truth["experiment"],
                effects=truth["effect_names"], contribution_counts_rms=truth["contribution_counts_rms"],
                plant_error=None if truth["plant_error"] is None else {
                    k: truth["plant_error"][k] for k in ("name", "factor", "contribution_counts_rms")},
                theta_column=truth["theta_column"], sample_period_s=truth["sample_period_s"],
                duration_s=truth["duration_s"], timing=truth["timing"]["kind"])


def _worker(args):
    out_dir, seed, index, duration = args
    truth = write_case(out_dir, seed, index, duration)
    return _summary(truth), truth["generation_s"]


def generate(out_dir, n_cases, seed, indices=None, workers=1, progress=None, duration=None):
    """Write cases (seed, i) for i in indices (default range(n_cases)) and DIR/manifest.json."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    indices = list(range(n_cases)) if indices is None else [int(i) for i in indices]
    jobs = [(str(out_dir), int(seed), i, duration) for i in indices]
    t0 = time.perf_counter()
    results = []
    if workers > 1:
        import multiprocessing as mp
        with mp.get_context("spawn").Pool(workers) as pool:
            for r in pool.imap(_worker, jobs):
                results.append(r)
                if progress:
                    progress(r[0]["case"], r[1])
    else:
        for j in jobs:
            r = _worker(j)
            results.append(r)
            if progress:
                progress(r[0]["case"], r[1])
    manifest = dict(generator="tests/independent/campaign.py", version=VERSION, seed=int(seed),
                    indices=indices, wall_s=round(time.perf_counter() - t0, 2),
                    generation_s={r[0]["case"]: r[1] for r in results},
                    cases={r[0]["case"]: r[0] for r in results})
    (out_dir / "manifest.json").write_text(json.dumps(_jsonable(manifest), indent=1, sort_keys=True))
    return manifest


def main(argv=None):
    ap = argparse.ArgumentParser(description="Randomised independent identification campaign (data + truth).")
    ap.add_argument("--out", required=True, help="output directory")
    ap.add_argument("--cases", type=int, default=40, help="number of cases (indices 0..N-1)")
    ap.add_argument("--seed", type=int, default=0, help="campaign seed")
    ap.add_argument("--indices", help="comma-separated case indices instead of 0..N-1")
    ap.add_argument("--workers", type=int, default=1, help="processes (default 1)")
    args = ap.parse_args(argv)
    indices = [int(i) for i in args.indices.split(",")] if args.indices else None

    def say(case, s):
        print(f"{case}: {s:.2f} s", flush=True)

    m = generate(args.out, args.cases, args.seed, indices, args.workers, say)
    print(f"wrote {len(m['cases'])} cases and manifest.json to {args.out} in {m['wall_s']:.1f} s")


if __name__ == "__main__":
    main()
