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

from .encoder import quantize
from .plant import CartPendulum
from .simulate import Simulator


@dataclass(frozen=True)
class PlantTruth:
    """Undeclared effects (all 0 = off).

    cogging_N, cogging_period_m : position-periodic force A sin(2 pi x / P) [N], [m]
    deadzone_V : input deadzone; |V| below it gives no force, above it V - sgn(V) dz [V]
    saturation_V : the drive cannot apply more than this [V] (0 = no limit)
    input_delay_s : transport delay of the command [s], a multiple of the sample period
    asymmetry_N : Coulomb level + asymmetry forward, - asymmetry backward [N]
    backlash_m : play between cart and its position encoder (rack and pinion) [m]
    bias_x_m, bias_theta_rad : constant sensor offsets [m], [rad]
    noise_x_m, noise_theta_rad : standard deviation of Gaussian sensor noise [m], [rad]
    noise_seed : seed of that noise
    """

    cogging_N: float = 0.0
    cogging_period_m: float = 0.01
    deadzone_V: float = 0.0
    saturation_V: float = 0.0
    input_delay_s: float = 0.0
    asymmetry_N: float = 0.0
    backlash_m: float = 0.0
    bias_x_m: float = 0.0
    bias_theta_rad: float = 0.0
    noise_x_m: float = 0.0
    noise_theta_rad: float = 0.0
    noise_seed: int = 1

    def to_dict(self) -> dict:
        return asdict(self)


def apply_input_effects(voltage: float, truth: PlantTruth) -> float:
    """Voltage that reaches the motor after deadzone and saturation [V]."""
    v = voltage
    dz = truth.deadzone_V
    if dz > 0.0:
        v = 0.0 if abs(v) <= dz else v - math.copysign(dz, v)
    if truth.saturation_V > 0.0:
        v = max(-truth.saturation_V, min(truth.saturation_V, v))
    return v


def play(previous: float, value: float, gap: float) -> float:
    """Backlash (play operator): the output follows ``value`` only beyond +/- gap/2."""
    half = 0.5 * gap
    if value > previous + half:
        return value - half
    if value < previous - half:
        return value + half
    return previous


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
                 resolution=(0.0, 0.0), track_limit: float = 0.4,
                 fallen_angle: float = math.radians(30.0)):
        self.effects = truth
        self.dt = dt
        self.resolution = resolution
        self.track_limit = track_limit
        self.fallen_angle = fallen_angle
        self.sim = Simulator(model, state0, extra_force=self._extra_force if self._has_force() else None)
        n = round(truth.input_delay_s / dt)
        self._pending = deque([0.0] * n)
        self._rng = random.Random(truth.noise_seed)
        self._backlash_x = self.sim.state[0]
        self.k = 0
        self.voltage_applied = 0.0

    def _has_force(self) -> bool:
        return self.effects.cogging_N != 0.0 or self.effects.asymmetry_N != 0.0

    def _extra_force(self, x: float, v: float) -> float:
        t = self.effects
        f = t.cogging_N * math.sin(2 * math.pi * x / t.cogging_period_m)
        if v != 0.0:
            f -= t.asymmetry_N
        return f

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
        x += t.bias_x_m
        th = s[1] + t.bias_theta_rad
        if t.noise_x_m:
            x += self._rng.gauss(0.0, t.noise_x_m)
        if t.noise_theta_rad:
            th += self._rng.gauss(0.0, t.noise_theta_rad)
        return quantize(x, self.resolution[0]), quantize(th, self.resolution[1])

    def step(self, voltage: float) -> None:
        """Hold ``voltage`` [V] (as commanded) for one sample period."""
        self._pending.append(voltage)
        v = apply_input_effects(self._pending.popleft(), self.effects)
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

    def limit_violation(self):
        """None, or (code, detail) when the track or fallen limit is crossed."""
        x, th = self.sim.state[0], self.sim.state[1]
        if not (math.isfinite(x) and math.isfinite(th)):
            return 'FALLEN', 'state is not finite'
        if abs(th) > self.fallen_angle:
            return 'FALLEN', f'|theta| = {abs(th):.3f} rad > {self.fallen_angle:.3f} rad'
        if abs(x) > self.track_limit:
            return 'TRACK_LIMIT', f'|x| = {abs(x):.3f} m > {self.track_limit:.3f} m'
        return None
