"""Offline closed loop: the rig and the controller sampled at 1 kHz, no ROS.

The same sequence the ROS lockstep loop performs: at sample k the encoders read the
rig, the controller computes V_k, the rig integrates [t_k, t_k+1) with V_k held.

Two engines run it. ``python`` steps the :class:`Rig` and :class:`StateFeedback` objects
(as the ROS nodes do). ``compiled`` runs the whole loop in one numba function built from
the same scalar functions (integrator, friction, plant, encoder, input effects,
velocity filter, feedback), so both give the same trajectory; it needs fresh objects
(nothing stepped yet) and covers every rig effect except sensor noise and a drive with play. ``auto`` takes
the compiled engine whenever it can.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..constants import DURATION, FALLEN, TRACK_LIMIT
from .compiled import compiled
from .controller import StateFeedback, feedback, filtered_rate
from .rig import Rig, input_effects, play, sensor_reading
from .simulate import advance, friction_now

ENGINES = ('auto', 'python', 'compiled')
#: how an offline run ends, by the compiled engine's code 0, 1, 2
END_REASONS = (DURATION, FALLEN, TRACK_LIMIT)


@dataclass
class Trajectory:
    """Sampled run. Arrays have one row per sample k (t_k = k dt)."""

    t: np.ndarray            # [s]
    state: np.ndarray        # true (x, theta, x', theta') at t_k
    measured: np.ndarray     # encoder (x, theta) at t_k
    voltage: np.ndarray      # V_k commanded for [t_k, t_k+1) [V]
    friction: np.ndarray     # friction force at t_k [N]
    stuck: np.ndarray        # cart held by static friction at t_k
    end_reason: str          # 'duration', 'FALLEN' or 'TRACK_LIMIT'


def compiled_unsupported(rig: Rig, controller: StateFeedback) -> str | None:
    """Why the compiled engine cannot run this rig and controller, or None if it can."""
    if type(controller) is not StateFeedback:
        return f'the controller is a {type(controller).__name__}, not a StateFeedback'
    if rig.k != 0:
        return 'the rig has already been stepped'
    if controller.started:
        return 'the controller has already been updated'
    if rig.effects.noise_x_m or rig.effects.noise_theta_rad:
        return 'sensor noise (plant_truth.noise_*) is drawn by the python engine only'
    if rig.effects.drive_backlash_m:
        return 'a drive with play (plant_truth.drive_backlash_m) is integrated by the python engine only'
    return None


def run_closed_loop(rig: Rig, controller: StateFeedback, duration: float,
                    engine: str = 'auto') -> Trajectory:
    """Run ``duration`` [s] of sampled feedback; stop early when a rig limit is crossed.

    ``engine``: 'python' advances ``rig`` and ``controller``; 'compiled' reads their
    settings and initial state and leaves them untouched; 'auto' = compiled if it can.
    """
    if engine not in ENGINES:
        raise ValueError(f'engine {engine!r}: expected one of {", ".join(ENGINES)}')
    why = compiled_unsupported(rig, controller)
    if engine == 'compiled' and why:
        raise ValueError(f'engine compiled: {why}; use engine python')
    n = int(round(duration / rig.dt)) + 1
    t, st = np.empty(n), np.empty((n, 4))
    meas, volt = np.empty((n, 2)), np.empty(n)
    fric, stuck = np.empty(n), np.zeros(n, bool)
    if engine == 'python' or why:
        m, reason = _run_python(rig, controller, n, t, st, meas, volt, fric, stuck)
    else:
        m, code = _run_compiled(rig, controller, n, t, st, meas, volt, fric, stuck)
        reason = END_REASONS[code]
    return Trajectory(t[:m], st[:m], meas[:m], volt[:m], fric[:m], stuck[:m], reason)


def warm_up(scenario) -> None:
    """Load the compiled functions the python engine calls (numba compiles them, or reads
    its cache, on first use), so that a ROS node's first real sample does not wait for it."""
    run_closed_loop(scenario.make_rig(), scenario.make_controller(), 0.002, engine='python')


def _run_python(rig, controller, n, t, st, meas, volt, fric, stuck):
    reason = DURATION
    k = 0
    for k in range(n):
        mx, mth = rig.measure()
        v = controller.update(mx, mth)
        tr = rig.truth()
        t[k], meas[k], volt[k] = rig.t, (mx, mth), v
        st[k] = tr['x'], tr['theta'], tr['x_dot'], tr['theta_dot']
        fric[k], stuck[k] = tr['friction_force'], tr['stuck']
        bad = rig.limit_violation()
        if bad:
            reason = bad[0]
            break
        if k < n - 1:
            rig.step(v)
    return k + 1, reason


def _run_compiled(rig, c, n, t, st, meas, volt, fric, stuck):
    r, f = rig.loop_spec(), c.loop_spec()
    return _loop(r.plant, r.friction, r.extra_force, r.state, r.mode, r.substep, r.dt, r.resolution,
                 r.sensors, r.drive, f.gain, f.control, r.limits, t, st, meas, volt, fric, stuck)


@compiled
def _loop(pp, fp, ef, s, mode, substep, dt, resolution, sensors, drive, gain, control, limits,
          t, st, meas, volt, fric, stuck):
    """The closed loop of :func:`_run_python`, compiled. Returns (samples, END_REASONS index)."""
    n = len(t)
    bias_x, bias_th, backlash = sensors
    deadzone, saturation, input_delay = drive[0], drive[1], int(drive[2])
    a, h, delay, vlimit = control[0], control[1], int(control[2]), control[3]
    track_limit, fallen_angle = limits
    history = np.empty((n, 4))
    bx, vx, vth, applied, now = s[0], 0.0, 0.0, 0.0, 0.0
    for k in range(n):
        if backlash > 0.0:
            bx = play(bx, s[0], backlash)
            x = bx
        else:
            x = s[0]
        mx, mth = sensor_reading(x, s[1], bias_x, bias_th, 0.0, 0.0, resolution)
        if k > 0:
            vx = filtered_rate(a, vx, meas[k - 1, 0], mx, h)
            vth = filtered_rate(a, vth, meas[k - 1, 1], mth, h)
        history[k, 0], history[k, 1], history[k, 2], history[k, 3] = mx, mth, vx, vth
        j = max(k - delay, 0)
        v = feedback(gain, (history[j, 0], history[j, 1], history[j, 2], history[j, 3]), vlimit)
        t[k], meas[k, 0], meas[k, 1], volt[k] = now, mx, mth, v
        st[k, 0], st[k, 1], st[k, 2], st[k, 3] = s[0], s[1], s[2], s[3]
        fric[k] = friction_now(pp, fp, ef, s, mode, applied)
        stuck[k] = mode[0] != 0.0
        if not (math.isfinite(s[0]) and math.isfinite(s[1])) or abs(s[1]) > fallen_angle:
            return k + 1, 1
        if abs(s[0]) > track_limit:
            return k + 1, 2
        if k < n - 1:
            applied = input_effects(volt[k - input_delay] if k >= input_delay else 0.0, deadzone, saturation)
            s, mode = advance(pp, fp, ef, s, mode, applied, dt, substep)
            now += dt
    return n, 0
