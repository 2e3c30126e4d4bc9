"""Offline closed loop: the rig and the controller sampled at 1 kHz, no ROS.

The same sequence the ROS lockstep loop performs: at sample k the encoders read the
rig, the controller computes V_k, the rig integrates [t_k, t_k+1) with V_k held.

Two engines run it. ``python`` steps the :class:`Rig` and :class:`StateFeedback` objects
(as the ROS nodes do). ``compiled`` runs the whole loop in one numba function built from
the same scalar functions (integrator, friction, plant, encoder, input effects,
velocity filter, feedback), so both give the same trajectory. Its state between samples is
one flat array (:func:`loop_start`), advanced by :func:`controller_sample`,
:func:`drive_command` and :func:`plant_segment`, which is what shooting for periodic orbits
varies; it needs fresh objects (nothing stepped yet) and covers every rig effect except
sensor noise and a drive with play. ``auto`` takes
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

__all__ = ['Trajectory', 'run_closed_loop', 'warm_up', 'LS_MODE', 'LS_APPLIED', 'LS_HELD', 'LS_PLAY', 'LS_LAST',
           'LS_RATE', 'LS_TIME', 'LS_HISTORY', 'loop_start', 'controller_sample', 'drive_command', 'plant_segment',
           'limit_code', 'LS_PLANT']

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
    return rig.compiled_unsupported()


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
    z = loop_start(r, f)
    return _loop(r.plant, r.friction, r.extra_force, r.substep, r.dt, r.resolution, r.sensors, r.drive,
                 f.gain, f.control, r.limits, z, t, st, meas, volt, fric, stuck)


# The loop's state between samples as one flat array (what shooting for periodic orbits varies):
#: plant (x, theta, x', theta', z) [SI], integrator mode (stuck, direction, events)
LS_PLANT, LS_MODE = 0, 5
#: voltage reaching the motor over the current interval [V] (before a sub-sample switch: the
#: previous one), encoder play output [m]
LS_APPLIED, LS_HELD, LS_PLAY = 8, 9, 10
#: previous readings (x [m], theta [rad]), filtered velocities [m/s, rad/s], time [s]
LS_LAST, LS_RATE, LS_TIME = 11, 13, 15
#: then the delayed estimates, ``delay`` rows of (x, theta, x', theta'), oldest first, then the
#: commands waiting for the drive's input delay [V], oldest first
LS_HISTORY = 16


def loop_state_size(delay: int, input_delay: int) -> int:
    """Length of the flat loop state for ``delay`` and ``input_delay`` [samples]."""
    return LS_HISTORY + 4 * delay + input_delay


def loop_start(r, f) -> np.ndarray:
    """Flat loop state of a fresh rig (``RigSpec``) and controller (``FeedbackSpec``).

    As :class:`StateFeedback` starts: the history is the first reading with zero velocity
    (eq. 30); no command waits in the drive.
    """
    delay, input_delay = int(f.control[2]), int(r.drive[2])
    z = np.zeros(loop_state_size(delay, input_delay))
    z[LS_PLANT:LS_PLANT + 5] = r.state
    z[LS_MODE:LS_MODE + 3] = r.mode
    z[LS_PLAY] = r.state[0]
    z[LS_LAST:LS_LAST + 2] = sensor_reading(r.state[0], r.state[1], r.sensors[0], r.sensors[1], 0.0, 0.0,
                                            r.resolution)
    for i in range(delay):
        z[LS_HISTORY + 4 * i:LS_HISTORY + 4 * i + 2] = z[LS_LAST:LS_LAST + 2]
    return z


@compiled
def controller_sample(resolution, sensors, gain, control, z):
    """Encoders read the rig, the controller estimates and commands: (x [m], theta [rad], V [V]).

    Updates the play, filter and history entries of the flat loop state ``z``.
    """
    bias_x, bias_th, backlash = sensors
    a, h, delay, vlimit = control[0], control[1], int(control[2]), control[3]
    x = z[LS_PLANT]
    if backlash > 0.0:
        z[LS_PLAY] = play(z[LS_PLAY], x, backlash)
        x = z[LS_PLAY]
    mx, mth = sensor_reading(x, z[LS_PLANT + 1], bias_x, bias_th, 0.0, 0.0, resolution)
    vx = filtered_rate(a, z[LS_RATE], z[LS_LAST], mx, h)
    vth = filtered_rate(a, z[LS_RATE + 1], z[LS_LAST + 1], mth, h)
    z[LS_LAST], z[LS_LAST + 1], z[LS_RATE], z[LS_RATE + 1] = mx, mth, vx, vth
    if delay == 0:
        return mx, mth, feedback(gain, (mx, mth, vx, vth), vlimit)
    o = LS_HISTORY
    v = feedback(gain, (z[o], z[o + 1], z[o + 2], z[o + 3]), vlimit)
    for i in range(4 * (delay - 1)):
        z[o + i] = z[o + i + 4]
    e = o + 4 * (delay - 1)
    z[e], z[e + 1], z[e + 2], z[e + 3] = mx, mth, vx, vth
    return mx, mth, v


@compiled
def drive_command(drive, control, z, v):
    """The command ``v`` [V] enters the drive; the voltage reaching the motor (after the input
    delay, deadzone and saturation) is held in ``z`` for the next interval [V]."""
    deadzone, saturation, input_delay = drive[0], drive[1], int(drive[2])
    z[LS_HELD] = z[LS_APPLIED]
    if input_delay == 0:
        z[LS_APPLIED] = input_effects(v, deadzone, saturation)
        return
    o = LS_HISTORY + 4 * int(control[2])
    z[LS_APPLIED] = input_effects(z[o], deadzone, saturation)
    for i in range(input_delay - 1):
        z[o + i] = z[o + i + 1]
    z[o + input_delay - 1] = v


@compiled
def plant_segment(pp, fp, ef, substep, z, start, end, switch):
    """Advance the plant in ``z`` from ``start`` to ``end`` [s] after a sample.

    The motor sees the previous interval's voltage until ``switch`` [s] and the new one after
    it: a feedback delay of a fraction ``switch`` / dt of a sample (0 = whole samples only).
    """
    for part in range(2):
        if part == 0:
            stop, voltage = min(end, switch), z[LS_HELD]
        else:
            stop, voltage = end, z[LS_APPLIED]
        if stop > start:
            s, mode = advance(pp, fp, ef, (z[0], z[1], z[2], z[3], z[4]), (z[5], z[6], z[7]), voltage,
                              stop - start, substep)
            z[0], z[1], z[2], z[3], z[4] = s
            z[5], z[6], z[7] = mode
            z[LS_TIME] += stop - start
            start = stop


@compiled
def limit_code(z, limits) -> int:
    """0 inside the rig's limits, else the index in END_REASONS (1 fallen or not finite, 2 track)."""
    if not (math.isfinite(z[0]) and math.isfinite(z[1])) or abs(z[1]) > limits[1]:
        return 1
    if abs(z[0]) > limits[0]:
        return 2
    return 0


@compiled
def _loop(pp, fp, ef, substep, dt, resolution, sensors, drive, gain, control, limits, z,
          t, st, meas, volt, fric, stuck):
    """The closed loop of :func:`_run_python`, compiled. Returns (samples, END_REASONS index)."""
    n = len(t)
    for k in range(n):
        mx, mth, v = controller_sample(resolution, sensors, gain, control, z)
        t[k], meas[k, 0], meas[k, 1], volt[k] = z[LS_TIME], mx, mth, v
        s = (z[0], z[1], z[2], z[3], z[4])
        st[k, 0], st[k, 1], st[k, 2], st[k, 3] = s[0], s[1], s[2], s[3]
        fric[k] = friction_now(pp, fp, ef, s, (z[5], z[6], z[7]), z[LS_APPLIED])
        stuck[k] = z[5] != 0.0
        code = limit_code(z, limits)
        if code:
            return k + 1, code
        if k < n - 1:
            drive_command(drive, control, z, v)
            plant_segment(pp, fp, ef, substep, z, 0.0, dt, 0.0)
    return n, 0
