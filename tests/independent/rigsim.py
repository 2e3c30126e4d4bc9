"""Independent simulator of the Campbell-Crawford-Morris cart-pendulum rig.

Written from the physics of the paper; it shares no code with ``ipfric_core``.
SI units throughout: x [m], theta [rad], t [s], voltage [V], force [N].

Plant, paper eq. (1)-(2) (pendulum a uniform rod, centre of mass at l [m] from
the pivot, inertia m l^2/3 about it; theta from upright, sign as in the paper):
    (M + m) x'' + m l cos(th) th'' - m l sin(th) th'^2 = F + F_fric + F_extra
    (4/3) m l^2 th'' + m l cos(th) x'' - m g l sin(th) = 0
    F = alpha u - beta x'          (alpha [N/V], beta [N s/m], u motor voltage [V])
Eliminating th'' gives, with N the force on the cart apart from friction at x'' = 0,
    N   = F + F_extra + m l sin(th) th'^2 - (3/4) m g sin(th) cos(th)
    x'' = (N + F_fric) / (M + m - (3/4) m cos(th)^2)
    th'' = 3 (g sin(th) - cos(th) x'') / (4 l)
Friction, paper eq. (8) with gamma = 2, F_N = (M + m) g (M g with the pendulum
removed, when m = 0 in the dynamics), Fc = mu_c F_N, Fs = mu_s F_N:
    sliding   F_fric = -(Fc + (Fs - Fc) exp(-(v / v_s)^2)) sgn(v) - eps v
    sticking  v = 0 and -Fs <= N <= Fs: the cart stays at rest (x'' = 0) while the
              pendulum swings with th'' = 3 g sin(th) / (4 l); otherwise it breaks
              away in the direction of N.
Integration: fixed-step RK4 (default 0.1 ms) with sgn(v) frozen inside each step;
a zero crossing of v is located by regula falsi (Illinois), v is set to 0 there
and the stick condition tested.
Smoothed friction (spec "smoothing": {"delta": d}, d [s/m]): sgn(v) becomes tanh(d v),
    F_fric = -(Fc + (Fs - Fc) exp(-(v / v_s)^2)) tanh(d v) - eps v,
the law is smooth and there is no sticking: plain RK4 steps, no stop located, no stick test.

Undeclared effects (at most one per file):
    deadzone   u = 0 if |V| <= dz else V - sgn(V) dz                       [V]
    backlash   motor-side mass Mb [kg] at the rack: Mb xb'' = alpha u - beta xb' - Fk;
               cart drive F = Fk, Fk = k (d -+ gap/2) + c (xb' - x') when |d| > gap/2
               (contact pushes only), else 0, d = xb - x. The encoder reads the CART.
    cogging    F_extra = A sin(2 pi x / P + phase)                          [N]
    asymmetry  Fc, Fs times (1 + a) moving/breaking forward, (1 - a) backward
    delay      u(t) = V(t - d), d a whole number of samples                 [s]
    bias       the angle encoder reads th + b                               [rad]
Sensors: readings are the true values rounded to encoder counts (a count of 0, set by
the spec's "rig_overrides" x_res / theta_res, reads the true value); the commanded
voltage V is held over each sample (zero-order hold). CSV voltage is the command V.
A spec may give "theta0" [rad], the initial pendulum angle of a closed loop (default THETA0).
Closed-loop spec keys (absent: as above):
    "K"                       the gain, V = K . (x, th, x', th') (default K_PAPER / LQR)
    "feedback_delay_samples"  n: the command at sample k uses the row r_(k-n) of readings and
                              filtered velocities (x_enc, th_enc, vx, vth) taken at sample k - n,
                              and (x_enc_0, th_enc_0, 0, 0), the first reading at rest, for k < n;
                              the filter itself runs every sample on the current readings. (The
                              "delay" effect instead delays the voltage and holds 0 V meanwhile.)
    "stop_when_fallen"        true: the run ends at the first sample with |th| > FALLEN or |x| >
                              TRACK (true state) and returns the samples so far, truth "end" =
                              "fallen" / "track" / "duration"; false (default): the whole run,
                              an error if the cart left the track.
"""

import argparse
import json
import math
import time
from pathlib import Path

import numba
import numpy as np
from scipy.linalg import solve_continuous_are

_jit = numba.njit(cache=True)     # compiled once per machine, into tests/independent/__pycache__

TRACK = 0.35                      # usable half-length of the track [m]
SUBSTEP = 1e-4                    # default internal integration step [s]
THETA_RES = 2 * math.pi / 4096    # angle encoder count [rad] (0.08789 deg)
FILTER_HZ = 20.0                  # low-pass corner of the velocity estimates [Hz]
VMAX = 10.0                       # controller voltage limit [V]
THETA0 = math.radians(2.0)        # initial pendulum angle of the closed loops [rad]
FALLEN = 0.5236                   # |theta| beyond which the pendulum has fallen [rad] (30 deg)
K_PAPER = (70.7107, 142.5409, 50.6911, 26.9817)   # gain (15): V = K . (x, th, x', th')
Q_LQR = (5000.0, 3000.0, 20.0, 20.0)               # paper's LQR state weight, r = 1

RIGS = {
    "quanser": dict(M=0.815, m=0.210, l=0.3050, g=9.8, alpha=1.7189, beta=7.682,
                    mu_s=0.08610, mu_c=0.04287, eps=3.0, v_s=0.105,
                    x_res=4.54e-5, theta_res=THETA_RES, Ts=1e-3),
    "ip02": dict(M=0.57, m=0.127, l=0.1778, g=9.8, alpha=1.55, beta=6.5,
                 mu_s=0.13, mu_c=0.088, eps=2.0, v_s=0.08,
                 x_res=2.275e-5, theta_res=THETA_RES, Ts=5e-3),
}

EFFECTS = {
    "none": {},
    "deadzone": {"deadzone_V": 0.3},
    "backlash": {"gap_m": 1.0e-3, "motor_mass_kg": 0.2, "k_N_per_m": 2e5,
                 "c_N_s_per_m": 50.0, "encoder_measures": "cart"},
    "cogging": {"amplitude_N": 0.3, "period_m": 0.010, "phase_rad": 1.0},
    "asymmetry": {"a": 0.4},
    "delay": {"delay_s": 0.010},
    "bias": {"angle_bias_rad": 0.005},
}


def _case(rig, experiment, effect="none", seed=0, timing="regular", theta_ref="upright"):
    return dict(rig=rig, experiment=experiment, effect=effect, seed=seed, timing=timing,
                theta_ref=theta_ref if experiment == "loop" else None,
                duration=90.0 if experiment == "cart" else 30.0)


CASES = {
    "cart_none": _case("quanser", "cart", seed=11),
    "cart_deadzone": _case("quanser", "cart", "deadzone", seed=12),
    "cart_backlash": _case("quanser", "cart", "backlash", seed=13),
    "cart_cogging": _case("quanser", "cart", "cogging", seed=14),
    "cart_asymmetry": _case("quanser", "cart", "asymmetry", seed=15),
    "cart_delay": _case("quanser", "cart", "delay", seed=16),
    "loop_none": _case("quanser", "loop", seed=21),
    "loop_deadzone": _case("quanser", "loop", "deadzone", seed=22),
    "loop_cogging": _case("quanser", "loop", "cogging", seed=23),
    "loop_asymmetry": _case("quanser", "loop", "asymmetry", seed=24),
    "loop_delay": _case("quanser", "loop", "delay", seed=25),
    "loop_bias": _case("quanser", "loop", "bias", seed=26),
    "loop_backlash": _case("quanser", "loop", "backlash", seed=27),
    "ip02_cart": _case("ip02", "cart", seed=31, timing="overrun"),
    "ip02_loop_hanging": _case("ip02", "loop", seed=32, timing="overrun", theta_ref="hanging"),
    "cart_jitter": _case("quanser", "cart", seed=41, timing="jitter"),
}

# Layout of the plant parameter vector p (_DELTA: tanh smoothing of sgn(v) [s/m], 0 = none).
(_M, _MP, _L, _G, _AL, _BE, _FC, _FS, _EPS, _VS, _ASYM,
 _CA, _CP, _CPH, _GAP, _MB, _KB, _CB, _DELTA) = range(19)


# ----------------------------------------------------------------------------- plant
@_jit
def _contact(d, dv, p):
    """Backlash contact force on the cart [N]; d = xb - x [m], dv = xb' - x' [m/s]."""
    half = 0.5 * p[_GAP]
    if d > half:
        return max(p[_KB] * (d - half) + p[_CB] * dv, 0.0)
    if d < -half:
        return min(p[_KB] * (d + half) + p[_CB] * dv, 0.0)
    return 0.0


@_jit
def _net(y, u, p):
    """N: force on the cart other than friction, taken at x'' = 0 [N]."""
    if p[_MB] > 0.0:
        drive = _contact(y[4] - y[0], y[5] - y[1], p)
    else:
        drive = p[_AL] * u - p[_BE] * y[1]
    s, c, m = math.sin(y[2]), math.cos(y[2]), p[_MP]
    cog = p[_CA] * math.sin(2.0 * math.pi * y[0] / p[_CP] + p[_CPH])
    return drive + cog + m * p[_L] * s * y[3] ** 2 - 0.75 * m * p[_G] * s * c


@_jit
def _deriv(y, u, sgn, stuck, p, dy):
    """State derivative, y = (x, x', th, th', xb, xb'); sgn = frozen sign of x' when sliding
    (with smoothing, p[_DELTA] > 0, tanh(delta x') is used instead)."""
    m, c = p[_MP], math.cos(y[2])
    acc = 0.0
    if p[_DELTA] > 0.0:
        fric = (-(p[_FC] + (p[_FS] - p[_FC]) * math.exp(-(y[1] / p[_VS]) ** 2)) * math.tanh(p[_DELTA] * y[1])
                - p[_EPS] * y[1])
        acc = (_net(y, u, p) + fric) / (p[_M] + m - 0.75 * m * c * c)
    elif not stuck:
        lev = 1.0 + p[_ASYM] * sgn
        fric = (-lev * (p[_FC] + (p[_FS] - p[_FC]) * math.exp(-(y[1] / p[_VS]) ** 2)) * sgn
                - p[_EPS] * y[1])
        acc = (_net(y, u, p) + fric) / (p[_M] + m - 0.75 * m * c * c)
    dy[0] = y[1]
    dy[1] = acc
    dy[2] = y[3]
    dy[3] = 0.75 * (p[_G] * math.sin(y[2]) - c * acc) / p[_L] if m > 0.0 else 0.0
    dy[4] = y[5]
    dy[5] = 0.0
    if p[_MB] > 0.0:
        dy[5] = (p[_AL] * u - p[_BE] * y[5] - _contact(y[4] - y[0], y[5] - y[1], p)) / p[_MB]


@_jit
def _rk4(y, h, u, sgn, stuck, p, w, out):
    """One classical RK4 step of size h [s] from y into out (out may be y)."""
    k1, k2, k3, k4, tmp = w[0], w[1], w[2], w[3], w[4]
    _deriv(y, u, sgn, stuck, p, k1)
    for i in range(6):
        tmp[i] = y[i] + 0.5 * h * k1[i]
    _deriv(tmp, u, sgn, stuck, p, k2)
    for i in range(6):
        tmp[i] = y[i] + 0.5 * h * k2[i]
    _deriv(tmp, u, sgn, stuck, p, k3)
    for i in range(6):
        tmp[i] = y[i] + h * k3[i]
    _deriv(tmp, u, sgn, stuck, p, k4)
    for i in range(6):
        out[i] = y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])


@_jit
def _to_rest(y, rem, u, sgn, p, w):
    """Advance y to the time in (0, rem] [s] where x' reaches 0; set x' = 0; return the time.

    On entry w[5] holds the state after a full step rem, where sgn * x' <= 0.
    """
    lo, flo = 0.0, sgn * y[1]
    hi, fhi = rem, sgn * w[5, 1]
    if flo <= 0.0:
        y[1] = 0.0
        return 0.0
    tau, side = hi, 0
    for _ in range(60):
        tau = lo + (hi - lo) * flo / (flo - fhi)
        _rk4(y, tau, u, sgn, False, p, w, w[6])
        f = sgn * w[6, 1]
        if abs(f) < 1e-10 or hi - lo < 1e-13:
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
    y[:] = w[6]
    y[1] = 0.0
    return tau


@_jit
def _substep(y, h, u, st, p, w):
    """Advance y by h [s]; st = (stuck flag, sign of sliding) is updated (not used with smoothing)."""
    if p[_DELTA] > 0.0:
        _rk4(y, h, u, 0, False, p, w, y)
        return
    rem = h
    for _ in range(8):
        if st[0] == 1:
            n = _net(y, u, p)
            if n > p[_FS] * (1.0 + p[_ASYM]):
                st[0], st[1] = 0, 1
            elif n < -p[_FS] * (1.0 - p[_ASYM]):
                st[0], st[1] = 0, -1
            else:
                _rk4(y, rem, u, 0, True, p, w, y)
                return
        _rk4(y, rem, u, st[1], False, p, w, w[5])
        if st[1] * w[5, 1] > 0.0:
            y[:] = w[5]
            return
        rem -= _to_rest(y, rem, u, st[1], p, w)
        st[0] = 1
        if rem <= 0.0:
            return
    _rk4(y, rem, u, st[1], st[0] == 1, p, w, y)


@_jit
def _run(t, nsub, mode, sched, target, gain, frozen, p, ctrl, y0):
    """Sampled experiment. Per sample k (time t[k] [s]): read the encoders, compute the command

    mode 0: V = sched;  mode 1: V = clip(sched + gain (target - x_enc), +-ctrl[5]);
    mode 2: V = clip(K . (x_enc, th_enc, vx, vth)_(k - ctrl[11]), +-ctrl[5]), K = ctrl[0:4],
    with vx, vth the backward differences low-passed at ctrl[4] [Hz] (the row of sample
    j = k - ctrl[11], or (x_enc, th_enc, 0, 0) of sample 0 while j < 0); then hold the motor
    voltage u = deadzone(V delayed by ctrl[7] samples, ctrl[6]) until t[k+1].
    ctrl[8] = angle bias [rad], ctrl[9], ctrl[10] = encoder counts [m], [rad] (0 = exact reading).
    ctrl[12] > 0: stop at the first sample with |th| > ctrl[12] [rad] (end code 1) or |x| >
    ctrl[13] [m] (end code 2), true state, after recording it. Returns the arrays and (samples
    recorded, end code 0 = whole run).
    """
    n = t.size
    xe, the, volt, um = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
    xt, vt, tht = np.zeros(n), np.zeros(n), np.zeros(n)
    vxs, vths = np.zeros(n), np.zeros(n)
    y = y0.copy()
    st = np.array([1, 1])
    w = np.zeros((7, 6))
    vlim, dz, dn, rx, rth = ctrl[5], ctrl[6], int(ctrl[7]), ctrl[9], ctrl[10]
    fn, fall, track = int(ctrl[11]), ctrl[12], ctrl[13]
    vx = vth = 0.0
    for k in range(n):
        if frozen[k] and k > 0:
            xe[k], the[k] = xe[k - 1], the[k - 1]
        else:
            xe[k] = rx * np.round(y[0] / rx) + 0.0 if rx > 0.0 else y[0]   # + 0.0: no negative zeros
            the[k] = rth * np.round((y[2] + ctrl[8]) / rth) + 0.0 if rth > 0.0 else y[2] + ctrl[8]
        if k > 0:
            dt = t[k] - t[k - 1]
            a = 1.0 - math.exp(-2.0 * math.pi * ctrl[4] * dt)
            vx += a * ((xe[k] - xe[k - 1]) / dt - vx)
            vth += a * ((the[k] - the[k - 1]) / dt - vth)
        vxs[k], vths[k] = vx, vth
        if mode[k] == 0:
            v = sched[k]
        elif mode[k] == 1:
            v = sched[k] + gain[k] * (target[k] - xe[k])
        elif k >= fn:
            j = k - fn
            v = ctrl[0] * xe[j] + ctrl[1] * the[j] + ctrl[2] * vxs[j] + ctrl[3] * vths[j]
        else:                      # the first reading at rest: (x_enc_0, th_enc_0, 0, 0)
            v = ctrl[0] * xe[0] + ctrl[1] * the[0]
        volt[k] = (v if mode[k] == 0 else min(max(v, -vlim), vlim)) + 0.0
        ud = volt[k - dn] if k >= dn else 0.0
        um[k] = 0.0 if abs(ud) <= dz else ud - math.copysign(dz, ud)
        xt[k], vt[k], tht[k] = y[0], y[1], y[2]
        if fall > 0.0 and (abs(y[2]) > fall or abs(y[0]) > track):
            return xe, the, volt, um, xt, vt, tht, k + 1, 1 if abs(y[2]) > fall else 2
        if k + 1 < n:
            h = (t[k + 1] - t[k]) / nsub[k]
            for _ in range(nsub[k]):
                _substep(y, h, um[k], st, p, w)
    return xe, the, volt, um, xt, vt, tht, n, 0


# ------------------------------------------------------------------------- design
def linear_model(rig, eps=None):
    """Upright linearization s' = A s + B V, s = (x, th, x', th'), viscous friction eps [N s/m]."""
    M, m, l, g = rig["M"], rig["m"], rig["l"], rig["g"]
    damp = rig["beta"] + (rig["eps"] if eps is None else eps)
    me = M + m / 4.0
    A = np.array([[0, 0, 1, 0], [0, 0, 0, 1],
                  [0, -0.75 * m * g / me, -damp / me, 0],
                  [0, 0.75 * g / l + 9 * m * g / (16 * l * me), 0.75 * damp / (l * me), 0]])
    B = np.array([[0.0], [0.0], [rig["alpha"] / me], [-0.75 * rig["alpha"] / (l * me)]])
    return A, B


def lqr_gain(rig, eps=None, Q=Q_LQR, r=1.0):
    """LQR gain K for V = K s (paper's sign convention), cost integral of s'Qs + r V^2."""
    A, B = linear_model(rig, eps)
    P = solve_continuous_are(A, B, np.diag(Q), np.array([[r]]))
    return -(B.T @ P)[0] / r


# ------------------------------------------------------------------------- experiments
def _stamps(timing, Ts, duration, rng):
    """Sample instants t [s] (exact), frozen-reading flags, and timing metadata."""
    n = int(round(duration / Ts)) + 1
    frozen = np.zeros(n, dtype=np.bool_)
    if timing == "regular":
        return np.arange(n) * Ts, frozen, {"kind": "regular"}
    if timing == "jitter":
        t = (np.arange(n) + rng.uniform(-0.3, 0.3, n)) * Ts
        t[0] = 0.0
        return t, frozen, {"kind": "jitter", "jitter_max_s": 0.3 * Ts,
                           "note": "samples taken at the stamped (irregular) times"}
    # overrun: the stamp jumps by 2-3 periods, then 1-3 readings repeat the previous one
    events = max(1, int(duration / 1.5))
    block = (n - 20) // events
    jumps = 10 + block * np.arange(events) + rng.integers(0, block - 8, events)
    steps = np.ones(n - 1, dtype=np.int64)
    steps[jumps - 1] = rng.integers(2, 4, events)
    ticks = np.concatenate([[0], np.cumsum(steps)])
    keep = ticks * Ts <= duration + 1e-9
    for j, f in zip(jumps, rng.integers(1, 4, events)):
        frozen[j + 1:j + 1 + f] = True
    jumps = jumps[jumps < keep.sum()]
    return ticks[keep] * Ts, frozen[keep], {
        "kind": "overrun", "jump_rows": jumps.tolist(),
        "frozen_rows": np.flatnonzero(frozen[keep]).tolist(),
        "note": "stamp jumps by 2-3 periods at jump_rows (voltage held meanwhile); "
                "frozen_rows repeat the previous encoder readings"}


def _cart_plan(rig, Fc, duration, rng):
    """Cart-alone experiment as a list of segments (kind, start [s], length [s], params)."""
    damp = rig["beta"] + rig["eps"]
    plan = []

    def add(kind, length, **params):
        start = plan[-1][1] + plan[-1][2] if plan else 0.0
        plan.append((kind, start, length, params))

    def move(target):
        add("reposition", 2.0, target=target, gain_V_per_m=30.0)
        add("rest", 0.5)

    for sign in (1, -1):
        move(-0.2 * sign)
        add("ramp", 4.0, rate_V_per_s=0.25 * sign)
        add("rest", 1.5)
    for volts in (1.0, 2.0, 3.0):
        for sign in (1, -1):
            move(-0.2 * sign)
            add("step", round(min(3.0, 0.3 * damp / (rig["alpha"] * volts - Fc)), 3),
                V=sign * volts)
            add("rest", 1.5)
    move(0.0)
    add("pulses", 6.0, V=2.0, width_s=0.1, period_s=1.0)
    move(0.0)
    freqs = np.unique(np.round(np.geomspace(0.1, 5.0, 14), 1))
    phases = rng.uniform(0.0, 2 * math.pi, freqs.size)
    tt = np.arange(0.0, 10.0, 1e-3)
    peak = np.abs(np.sin(2 * math.pi * np.outer(tt, freqs) + phases).sum(axis=1)).max()
    used = plan[-1][1] + plan[-1][2]
    add("multisine", max(10.0, duration - used), freqs_Hz=freqs.tolist(),
        phases_rad=phases.tolist(), amplitude_V=round(2.5 / peak, 6), offset_V=0.2,
        target=0.0, gain_V_per_m=10.0)
    return plan


def _plan_signals(plan, t):
    """Per-sample mode, open-loop voltage [V], position target [m] and loop gain [V/m]."""
    n = t.size
    mode, sched = np.zeros(n, dtype=np.int64), np.zeros(n)
    target, gain = np.zeros(n), np.zeros(n)
    starts = np.array([seg[1] for seg in plan])
    idx = np.searchsorted(starts, t, side="right") - 1
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
            sched[sel] = q["V"] * ((ph < q["width_s"]) * 1.0
                                   - ((ph >= half) & (ph < half + q["width_s"])))
        elif kind == "multisine":
            arg = 2 * math.pi * np.outer(tau, q["freqs_Hz"]) + np.array(q["phases_rad"])
            sched[sel] = q["offset_V"] + q["amplitude_V"] * np.sin(arg).sum(axis=1)
    return mode, sched, target, gain


def _wrap(a):
    """Angle wrapped to (-pi, pi] [rad]."""
    return math.pi - np.mod(math.pi - a, 2 * math.pi)


def simulate(spec, duration=None, substep=SUBSTEP):
    """Run one case spec (see CASES); returns dict t, x, voltage, theta|None, truth, state."""
    rig = dict(RIGS[spec["rig"]], **spec.get("rig_overrides", {}))
    cart = spec["experiment"] == "cart"
    duration = float(duration or spec["duration"])
    rng = np.random.default_rng(spec["seed"])
    Ts = rig["Ts"]
    t, frozen, timing = _stamps(spec["timing"], Ts, duration, rng)
    m = 0.0 if cart else rig["m"]
    FN = (rig["M"] + m) * rig["g"]
    Fc, Fs = rig["mu_c"] * FN, rig["mu_s"] * FN
    effect = spec["effect"]
    size = dict(EFFECTS[effect], **spec.get("size", {}))
    loop_keys = {"K", "feedback_delay_samples", "stop_when_fallen"} & set(spec)
    if cart and loop_keys:
        raise ValueError(f"closed-loop keys in a cart experiment: {sorted(loop_keys)}")
    smoothing = spec.get("smoothing")
    if smoothing is not None and not smoothing["delta"] > 0.0:
        raise ValueError(f"smoothing delta = {smoothing['delta']!r}: must be > 0 [s/m]")
    if smoothing is not None and effect == "asymmetry":
        raise ValueError("smoothing and the asymmetry effect together are not defined")
    fb_n = int(spec.get("feedback_delay_samples", 0))
    if fb_n != spec.get("feedback_delay_samples", 0) or fb_n < 0:
        raise ValueError(f"feedback_delay_samples = {spec['feedback_delay_samples']!r}: a whole number >= 0")
    stop = bool(spec.get("stop_when_fallen", False))
    p = np.zeros(19)
    p[[_M, _MP, _L, _G, _AL, _BE, _FC, _FS, _EPS, _VS]] = (
        rig["M"], m, rig["l"], rig["g"], rig["alpha"], rig["beta"], Fc, Fs, rig["eps"], rig["v_s"])
    p[_CP] = 1.0
    if effect == "asymmetry":
        p[_ASYM] = size["a"]
    elif effect == "cogging":
        p[[_CA, _CP, _CPH]] = size["amplitude_N"], size["period_m"], size["phase_rad"]
    elif effect == "backlash":
        p[[_GAP, _MB, _KB, _CB]] = (size["gap_m"], size["motor_mass_kg"], size["k_N_per_m"],
                                    size["c_N_s_per_m"])
    if smoothing is not None:
        p[_DELTA] = smoothing["delta"]
    K = np.zeros(4)
    truth = {}
    if cart:
        plan = _cart_plan(rig, Fc, duration, rng)
        mode, sched, target, gain = _plan_signals(plan, t)
        truth["segments"] = [dict(kind=k, t0=round(s, 6), t1=round(s + d, 6), **q)
                             for k, s, d, q in plan if s < t[-1]]
        vlim = 4.0
    else:
        if "K" in spec:
            K = np.array(spec["K"], dtype=float)
            if K.shape != (4,) or not np.isfinite(K).all():
                raise ValueError(f"K = {spec['K']!r}: 4 finite gains (x, th, x', th')")
        else:
            K = np.array(K_PAPER) if spec["rig"] == "quanser" else lqr_gain(rig)
        mode = np.full(t.size, 2, dtype=np.int64)
        sched, target, gain = np.zeros(t.size), np.zeros(t.size), np.zeros(t.size)
        truth["controller"] = dict(
            law="V = K . (x, theta_up, x', theta_up') from encoder readings, clipped",
            K=K.tolist(), velocity_filter=f"backward difference, first-order low-pass {FILTER_HZ} Hz",
            voltage_limit_V=VMAX, excitation=None)
        if "feedback_delay_samples" in spec:
            truth["controller"].update(
                feedback_delay_samples=fb_n,
                feedback_delay_note="V_k from the row (x_enc, th_enc, vx, vth) of sample k - n; "
                                    "(x_enc_0, th_enc_0, 0, 0) for k < n")
        vlim = VMAX
    delay_n = int(round(size.get("delay_s", 0.0) / Ts))
    if effect == "delay":
        size["delay_samples"] = delay_n
    ctrl = np.array([*K, FILTER_HZ, vlim, size.get("deadzone_V", 0.0), delay_n,
                     size.get("angle_bias_rad", 0.0), rig["x_res"], rig["theta_res"], fb_n,
                     FALLEN if stop else 0.0, TRACK])
    y0 = np.array([0.0, 0.0, 0.0 if cart else spec.get("theta0", THETA0), 0.0, 0.0, 0.0])
    nsub = np.maximum(1, np.ceil(np.diff(t) / substep - 1e-9)).astype(np.int64)
    *arrays, rows, end = _run(t, nsub, mode, sched, target, gain, frozen, p, ctrl, y0)
    t = t[:rows]
    xe, the, volt, um, xt, vt, tht = (a[:rows] for a in arrays)
    if not stop and np.abs(xt).max() > TRACK:
        raise RuntimeError(f"cart left the track: max |x| = {np.abs(xt).max():.3f} m")
    theta = None
    if not cart:
        theta = _wrap(the + math.pi) if spec["theta_ref"] == "hanging" else the
    truth.update(
        effect=effect, effect_size=size, rig=spec["rig"], experiment=spec["experiment"],
        pendulum_attached=not cart,
        constants={k: rig[k] for k in ("M", "m", "l", "g", "alpha", "beta")},
        friction=dict(model="exponential (Stribeck), true stick-slip" if smoothing is None
                      else "exponential (Stribeck), sgn(v) smoothed to tanh(delta v), no sticking",
                      mu_s=rig["mu_s"], mu_c=rig["mu_c"], eps=rig["eps"], v_s=rig["v_s"], gamma=2.0,
                      F_N=FN, Fc=Fc, Fs=Fs, **({} if smoothing is None else {"delta": p[_DELTA]})),
        sample_period_s=Ts, timing=timing, rows=int(t.size), duration_s=float(t[-1]),
        columns=["t", "x", "voltage"] + ([] if cart else ["theta"]),
        theta_reference=spec["theta_ref"],
        theta_note=None if cart else ("theta + pi wrapped to (-pi, pi] (pi = upright)"
                                      if spec["theta_ref"] == "hanging" else "0 = upright"),
        encoder=dict(x_count_m=rig["x_res"], theta_count_rad=rig["theta_res"],
                     x_measures="cart",
                     rounding="nearest count" if rig["x_res"] > 0 and rig["theta_res"] > 0
                     else "nearest count (a count of 0: exact reading)"),
        initial_state=dict(x=0.0, theta=float(y0[2]), x_dot=0.0, theta_dot=0.0),
        voltage="command before deadzone/delay, zero-order hold", substep_s=substep,
        seed=spec["seed"], max_abs_x_true=float(np.abs(xt).max()),
        max_abs_theta_true=None if cart else float(np.abs(tht).max()))
    if stop:
        truth["end"] = ("duration", "fallen", "track")[end]
    return dict(t=t, x=xe, voltage=volt, theta=theta, truth=truth,
                state=dict(x=xt, v=vt, theta=tht, u=um))


def generate(name, duration=None, substep=SUBSTEP):
    """Simulate case `name` of CASES; see simulate()."""
    out = simulate(CASES[name], duration, substep)
    out["truth"]["case"] = name
    return out


def write_case(name, out_dir, duration=None, data=None):
    """Write DIR/<name>.csv (t [s], x [m], voltage [V][, theta [rad]]); return its path."""
    data = data or generate(name, duration)
    cols = [data["t"], data["x"], data["voltage"]]
    if data["theta"] is not None:
        cols.append(data["theta"])
    path = Path(out_dir) / f"{name}.csv"
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savetxt(path, np.column_stack(cols), fmt="%.9g", delimiter=",",
               header=",".join(data["truth"]["columns"]), comments="")
    return path


def main(argv=None):
    ap = argparse.ArgumentParser(description="Independent rig data for ipfric identification tests.")
    ap.add_argument("--out", required=True, help="output directory")
    ap.add_argument("--cases", default=",".join(CASES), help="comma-separated case names")
    ap.add_argument("--duration", type=float, default=None, help="seconds per case (default per case)")
    args = ap.parse_args(argv)
    names = [c for c in args.cases.split(",") if c]
    unknown = set(names) - set(CASES)
    if unknown:
        ap.error(f"unknown cases: {sorted(unknown)}")
    manifest = {}
    t_all = time.perf_counter()
    for i, name in enumerate(names, 1):
        t0 = time.perf_counter()
        data = generate(name, args.duration)
        path = write_case(name, args.out, data=data)
        manifest[name] = dict(file=path.name, **data["truth"])
        print(f"[{i}/{len(names)}] {name}: {data['t'].size} rows, effect {data['truth']['effect']}, "
              f"{time.perf_counter() - t0:.2f} s", flush=True)
    (Path(args.out) / "manifest.json").write_text(json.dumps(manifest, indent=1))
    print(f"wrote {len(names)} cases and manifest.json to {args.out} "
          f"in {time.perf_counter() - t_all:.1f} s")


if __name__ == "__main__":
    main()
