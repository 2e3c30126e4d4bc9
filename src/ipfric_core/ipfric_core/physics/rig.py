"""The true rig: the plant model plus effects the design model does not declare.

``PlantTruth`` lists the undeclared effects (the ``plant_truth`` section of a scenario),
each with physical units; ``Rig`` samples the plant as the real sensors and drive do:
input effects on the commanded voltage, extra forces on the cart, sensor effects and
encoder quantization on the measurement. Every effect is off at its default.
"""
from __future__ import annotations

import math
import random
from collections import deque
from dataclasses import asdict, dataclass

import numpy as np

from ..constants import FALLEN, FALLEN_ANGLE_RAD, TRACK_LIMIT, TRACK_LIMIT_M
from .compiled import compiled
from .encoder import quantize
from .params import Field, FrictionParams, check_fields
from .plant import CartPendulum
from .simulate import Simulator

__all__ = ['PlantTruth', 'input_effects', 'inputs_through', 'play', 'sensor_reading', 'RigSpec', 'Rig',
           'PLANT_TRUTH_FIELDS', 'delayed_pieces', 'drive_pieces', 'drive_means', 'lag_response', 'lagged_commands']


#: the schema of :class:`PlantTruth`: unit, range and meaning of every field (its default is the dataclass's)
PLANT_TRUTH_FIELDS = {
    'cogging_sin_N': Field('N', -100.0, 100.0, 'position-periodic force, coefficient of sin(2 pi x / P)'),
    'cogging_cos_N': Field('N', -100.0, 100.0, 'position-periodic force, coefficient of cos(2 pi x / P)'),
    'cogging_period_m': Field('m', 0.0, 10.0, 'period P of the position-periodic force', lo_open=True),
    'offset_N': Field('N', -100.0, 100.0, 'constant force on the cart'),
    'asymmetry': Field('', -0.9, 0.9, 'friction level (1 + a) forward, (1 - a) backward'),
    'asymmetry_viscous_Ns_per_m': Field('N s/m', -100.0, 100.0, 'viscous coefficient + forward, - backward'),
    'deadzone_V': Field('V', 0.0, 100.0, 'input deadzone'),
    'saturation_V': Field('V', 0.0, 1e3, 'drive saturation (0 = none)'),
    'input_delay_s': Field('s', 0.0, 10.0, 'transport delay of the command'),
    'input_lag_s': Field('s', 0.0, 1.0, 'time constant of the drive\'s first-order lag (amplifier, motor current)'),
    'backlash_m': Field('m', 0.0, 1.0, 'play between cart and its encoder'),
    'drive_backlash_m': Field('m', 0.0, 1.0, 'play between the motor side of the drive and the cart'),
    'drive_mass_kg': Field('kg', 0.0, 100.0, 'motor side of the drive reflected to the rack (with a play)'),
    'drive_stiffness_N_per_m': Field('N/m', 0.0, 1e6, 'stiffness of the drive\'s contact beyond its play'),
    'drive_damping_Ns_per_m': Field('N s/m', 0.0, 1e3, 'damping of the drive\'s contact beyond its play'),
    'bias_x_m': Field('m', -1.0, 1.0, 'cart sensor offset'),
    'bias_theta_rad': Field('rad', -1.0, 1.0, 'angle sensor offset'),
    'noise_x_m': Field('m', 0.0, 1.0, 'cart sensor noise (std)'),
    'noise_theta_rad': Field('rad', 0.0, 1.0, 'angle sensor noise (std)'),
    'noise_seed': Field('', 0, 2 ** 31 - 1, 'seed of the sensor noise', integer=True),
}


@dataclass(frozen=True)
class PlantTruth:
    """Undeclared effects (all 0 = off); the schema of each field is :data:`PLANT_TRUTH_FIELDS`.

    cogging_sin_N, cogging_cos_N, cogging_period_m : position-periodic force
        a sin(2 pi x / P) + b cos(2 pi x / P) [N], [N], [m] (:func:`cogging_amplitude_phase`)
    offset_N : constant force on the cart (a sloped track, an amplifier offset) [N]
    asymmetry : friction level (1 + a) forward, (1 - a) backward, static friction included
    asymmetry_viscous_Ns_per_m : viscous coefficient eps + dF_v forward, eps - dF_v backward
    deadzone_V : input deadzone; |V| below it gives no force, above it V - sgn(V) dz [V]
    saturation_V : the drive cannot apply more than this [V] (0 = no limit)
    input_delay_s : transport delay of the command [s] (:func:`delayed_pieces`); a rig runs
        whole samples of it
    input_lag_s : time constant of a first-order lag between the (delayed) command and the voltage
        the motor sees (an amplifier, a current loop) [s] (:func:`lag_response`)
    backlash_m : play between cart and its position encoder (rack and pinion) [m]
    drive_backlash_m : play between the motor side of the drive and the cart [m]; the motor
        side (rotor and gears reflected to the rack) crosses it without pushing the cart
        (two-mass drive, ``simulate.advance_drive``); with it:
    drive_mass_kg : that motor side's mass reflected to the rack [kg], > 0
    drive_stiffness_N_per_m, drive_damping_Ns_per_m : its contact with the cart beyond the play,
        k [N/m] > 0 and c [N s/m] (``plant.drive_contact_force``)
    bias_x_m, bias_theta_rad : constant sensor offsets [m], [rad]
    noise_x_m, noise_theta_rad : standard deviation of Gaussian sensor noise [m], [rad]
    noise_seed : seed of that noise
    """

    cogging_sin_N: float = 0.0
    cogging_cos_N: float = 0.0
    cogging_period_m: float = 0.01
    offset_N: float = 0.0
    asymmetry: float = 0.0
    asymmetry_viscous_Ns_per_m: float = 0.0
    deadzone_V: float = 0.0
    saturation_V: float = 0.0
    input_delay_s: float = 0.0
    input_lag_s: float = 0.0
    backlash_m: float = 0.0
    drive_backlash_m: float = 0.0
    drive_mass_kg: float = 0.0
    drive_stiffness_N_per_m: float = 0.0
    drive_damping_Ns_per_m: float = 0.0
    bias_x_m: float = 0.0
    bias_theta_rad: float = 0.0
    noise_x_m: float = 0.0
    noise_theta_rad: float = 0.0
    noise_seed: int = 1

    @classmethod
    def from_dict(cls, data, path: str = 'plant_truth') -> PlantTruth:
        """Validated against :data:`PLANT_TRUTH_FIELDS` (absent fields: off); errors name ``path.field``."""
        return cls(**check_fields(path, data, PLANT_TRUTH_FIELDS))

    def to_dict(self) -> dict:
        return asdict(self)

    def force_vector(self) -> tuple:
        """The forces fixed to the track as ``plant.undeclared_force`` takes them."""
        return (float(self.cogging_sin_N), float(self.cogging_cos_N), float(self.cogging_period_m),
                float(self.offset_N))

    def drive_vector(self) -> tuple:
        """(play [m], motor-side mass [kg], contact stiffness [N/m], damping [N s/m]) of the drive, as
        ``simulate.advance_drive`` takes them."""
        return (float(self.drive_backlash_m), float(self.drive_mass_kg), float(self.drive_stiffness_N_per_m),
                float(self.drive_damping_Ns_per_m))

    def true_friction(self, friction: FrictionParams) -> FrictionParams:
        """The declared friction law with the rig's direction dependence added."""
        if not (self.asymmetry or self.asymmetry_viscous_Ns_per_m):
            return friction
        return friction.replace(asymmetry=friction.asymmetry + self.asymmetry,
                                asymmetry_viscous=friction.asymmetry_viscous + self.asymmetry_viscous_Ns_per_m)


@compiled
def input_effects(voltage: float, deadzone: float, saturation: float) -> float:
    """Voltage that reaches the motor after a deadzone and a saturation [V] (0 = off)."""
    v = voltage
    if deadzone > 0.0:
        v = 0.0 if abs(v) <= deadzone else v - math.copysign(deadzone, v)
    if saturation > 0.0:
        v = max(-saturation, min(saturation, v))
    return v


@compiled
def inputs_through(u, deadzone: float, saturation: float):
    """:func:`input_effects` along sampled inputs ``u``."""
    out = np.empty(len(u))
    for k in range(len(u)):
        out[k] = input_effects(u[k], deadzone, saturation)
    return out


def delayed_pieces(t, u, delay: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The command as the drive applies it through a transport delay ``delay`` [s]: each command u_k
    is held from its stamp t_k to the next and reaches the motor ``delay`` later, over
    [t_k + delay, t_k+1 + delay) (before the first of them: u_0). Returns, per sample interval
    [t_k, t_k+1), its pieces of constant applied command: ``first`` (n offsets: the pieces of
    interval k are first[k] .. first[k+1] - 1, first[n-1] is their count), the pieces' durations
    [s] and commands. Without a delay each interval is one piece, (t_k+1 - t_k, u_k); a delay of
    whole samples on even stamps shifts the commands by those samples (the rig's FIFO, :class:`Rig`).
    """
    t, u = np.asarray(t, float), np.asarray(u, float)
    n = len(t)
    if delay <= 0.0:
        return np.arange(n), np.diff(t), u[:max(n - 1, 0)].copy()
    tol = 1e-9 * float(np.median(np.diff(t))) if n > 1 else 0.0
    switches = t + delay
    near = np.clip(np.searchsorted(t, switches), 0, n - 1)
    for cand in (near, np.maximum(near - 1, 0)):
        snap = np.abs(t[cand] - switches) <= tol
        switches[snap] = t[cand][snap]
    edges = np.union1d(t, switches[(switches > t[0]) & (switches < t[-1])])
    starts = edges[:-1]
    j = np.searchsorted(t, starts - delay + tol, side='right') - 1
    values = u[np.maximum(j, 0)]
    owner = np.searchsorted(t, starts + tol, side='right') - 1
    first = np.searchsorted(owner, np.arange(n))
    return first, np.diff(edges), values


def drive_pieces(t, u, delay: float = 0.0, lag: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The command as the motor sees it before the deadzone and saturation: through the transport delay
    (:func:`delayed_pieces`) and the lag (:func:`lagged_commands`, each piece's mean); the pieces of
    :func:`delayed_pieces`."""
    first, durations, commands = delayed_pieces(t, u, delay)
    if lag > 0.0:
        commands = lagged_commands(durations, np.ascontiguousarray(commands, float), lag)
    return first, durations, commands


def drive_means(t, u, delay: float = 0.0, lag: float = 0.0) -> np.ndarray:
    """The mean command the motor sees over each sample interval (:func:`drive_pieces`); at the last
    sample, the last piece's. Without a delay or lag: ``u``."""
    u = np.asarray(u, float)
    if delay <= 0.0 and lag <= 0.0:
        return u
    first, durations, commands = drive_pieces(t, u, delay, lag)
    means = np.add.reduceat(durations * commands, first[:-1]) / np.add.reduceat(durations, first[:-1])
    return np.concatenate([means, commands[-1:]])


@compiled
def lag_response(state: float, command: float, tau: float, h: float):
    """A first-order lag, tau v' = command - v, over ``h`` [s] with ``command`` held, from v = ``state``:
    (mean of v over the interval, v at its end) [V]; the mean is what the drive applies over it (the
    force's impulse is exact). Without a lag (tau = 0): (command, command)."""
    if tau <= 0.0:
        return command, command
    e = math.exp(-h / tau)
    return command + (state - command) * tau / h * (1.0 - e), command + (state - command) * e


@compiled
def lagged_commands(durations, commands, tau: float):
    """:func:`lag_response` along pieces of held command (``durations`` [s], ``commands``), from rest at
    the first command: the mean voltage over each piece."""
    out = np.empty(len(commands))
    v = commands[0] if len(commands) else 0.0
    for j in range(len(commands)):
        out[j], v = lag_response(v, commands[j], tau, durations[j])
    return out


def apply_input_effects(voltage: float, truth: PlantTruth) -> float:
    """Voltage that reaches the motor after the rig's deadzone and saturation [V]."""
    return input_effects(float(voltage), truth.deadzone_V, truth.saturation_V)


@compiled
def play(previous: float, value: float, gap: float) -> float:
    """Backlash (play operator): the output follows ``value`` only beyond +/- gap/2."""
    half = 0.5 * gap
    if value > previous + half:
        return value - half
    if value < previous - half:
        return value + half
    return previous


@compiled
def sensor_reading(x, theta, bias_x, bias_theta, noise_x, noise_theta, resolution):
    """Encoder readings (x [m], theta [rad]): offsets and noise added, then quantized."""
    return (quantize(x + bias_x + noise_x, resolution[0]),
            quantize(theta + bias_theta + noise_theta, resolution[1]))


@dataclass(frozen=True)
class RigSpec:
    """A :class:`Rig` as numbers, what the compiled closed loop takes (SI units).

    plant, friction, extra_force : the vectors of ``plant.rates``
    state, mode : the integrator's (x, theta, x', theta', z) and (stuck, direction, events)
    substep, dt : largest RK4 step and sample period [s]
    resolution : encoder counts (cart [m], angle [rad])
    sensors : (bias x [m], bias theta [rad], backlash [m])
    drive : (deadzone [V], saturation [V], input delay [samples])
    limits : (track limit [m], fallen angle [rad])
    """

    plant: tuple
    friction: tuple
    extra_force: tuple
    state: tuple
    mode: tuple
    substep: float
    dt: float
    resolution: tuple
    sensors: tuple
    drive: tuple
    limits: tuple


class Rig:
    """Samples the true plant at period ``dt`` [s] with zero-order-hold voltage.

    Parameters
    ----------
    model : CartPendulum
    truth : PlantTruth
    state0 : initial state (x, theta, x', theta'[, z])
    dt : sample period [s]
    resolution : (cart [m], angle [rad]) encoder resolutions
    track_limit : |x| [m] beyond which the run ends
    fallen_angle : |theta| [rad] beyond which the pendulum has fallen
    """

    def __init__(self, model: CartPendulum, truth: PlantTruth, state0, dt: float,
                 resolution=(0.0, 0.0), track_limit: float = TRACK_LIMIT_M,
                 fallen_angle: float = FALLEN_ANGLE_RAD):
        self.effects = truth
        self.dt = dt
        self.resolution = resolution
        self.track_limit = track_limit
        self.fallen_angle = fallen_angle
        friction = truth.true_friction(model.friction.params)
        if friction is not model.friction.params:
            model = CartPendulum(model.p, friction, model.friction.normal_force)
        self.sim = Simulator(model, state0, extra_force=truth.force_vector(), drive=truth.drive_vector())
        n = round(truth.input_delay_s / dt)
        self._pending = deque([0.0] * n)
        self._lagged = 0.0
        self._rng = random.Random(truth.noise_seed)
        self._backlash_x = self.sim.state[0]
        self.k = 0
        self.voltage_applied = 0.0

    @property
    def t(self) -> float:
        return self.sim.t

    def measure(self) -> tuple[float, float]:
        """Encoder readings (x [m], theta [rad]) of the current sample."""
        t, s = self.effects, self.sim.state
        if t.backlash_m > 0.0:
            self._backlash_x = play(self._backlash_x, s[0], t.backlash_m)
            x = self._backlash_x
        else:
            x = s[0]
        nx = self._rng.gauss(0.0, t.noise_x_m) if t.noise_x_m else 0.0
        nth = self._rng.gauss(0.0, t.noise_theta_rad) if t.noise_theta_rad else 0.0
        return sensor_reading(x, s[1], t.bias_x_m, t.bias_theta_rad, nx, nth, self.resolution)

    def step(self, voltage: float) -> None:
        """Hold ``voltage`` [V] (as commanded) for one sample period."""
        self._pending.append(voltage)
        v, self._lagged = lag_response(self._lagged, self._pending.popleft(), self.effects.input_lag_s, self.dt)
        v = apply_input_effects(v, self.effects)
        self.voltage_applied = v
        self.sim.step(v, self.dt)
        self.k += 1

    def truth(self) -> dict:
        """Ground truth of the current sample (SI units)."""
        s = self.sim.state
        return {'x': s[0], 'theta': s[1], 'x_dot': s[2], 'theta_dot': s[3],
                'friction_force': self.sim.friction_force(self.voltage_applied),
                'z': s[4] if len(s) == 5 else 0.0, 'stuck': self.sim.stuck,
                'voltage_applied': self.voltage_applied}

    def loop_spec(self) -> RigSpec:
        """The rig's settings and current state as numbers (see :class:`RigSpec`); ValueError for an effect
        the compiled loop does not carry (:meth:`compiled_unsupported`)."""
        why = self.compiled_unsupported()
        if why:
            raise ValueError(f'the compiled loop cannot run this rig: {why}')
        e, sim = self.effects, self.sim
        return RigSpec(plant=sim.model.vector, friction=sim.model.friction.vector, extra_force=sim.extra_force,
                       state=sim.state_tuple, mode=sim.mode, substep=sim.substep, dt=float(self.dt),
                       resolution=(float(self.resolution[0]), float(self.resolution[1])),
                       sensors=(float(e.bias_x_m), float(e.bias_theta_rad), float(e.backlash_m)),
                       drive=(float(e.deadzone_V), float(e.saturation_V), float(len(self._pending))),
                       limits=(float(self.track_limit), float(self.fallen_angle)))

    def compiled_unsupported(self) -> str | None:
        """The effect of this rig the compiled loop does not carry (the python engine does), or None."""
        e = self.effects
        if e.noise_x_m or e.noise_theta_rad:
            return 'sensor noise (plant_truth.noise_*) is drawn by the python engine only'
        if e.drive_backlash_m:
            return 'a drive with play (plant_truth.drive_backlash_m) is integrated by the python engine only'
        if e.input_lag_s:
            return 'a drive lag (plant_truth.input_lag_s) is applied by the python engine only'
        return None

    def limit_violation(self):
        """None, or (code, detail) when the track or fallen limit is crossed."""
        x, th = self.sim.state[0], self.sim.state[1]
        if not (math.isfinite(x) and math.isfinite(th)):
            return FALLEN, 'state is not finite'
        if abs(th) > self.fallen_angle:
            return FALLEN, f'|theta| = {abs(th):.3f} rad > {self.fallen_angle:.3f} rad'
        if abs(x) > self.track_limit:
            return TRACK_LIMIT, f'|x| = {abs(x):.3f} m > {self.track_limit:.3f} m'
        return None
