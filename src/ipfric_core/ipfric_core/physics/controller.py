"""Discrete state-feedback controller of the rig: V = K s(t - tau), paper eqs. (13) and (26).

Positions come from encoders (no velocities); velocities are estimated by a
first-order low-pass filtered backward difference. The ROS controller node and the
offline closed loop both use :class:`StateFeedback`, so they compute the same commands.
"""
from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

from .compiled import compiled

__all__ = ['delay_samples', 'gain_vector', 'filter_coefficient', 'filtered_rate', 'feedback', 'FeedbackSpec',
           'StateFeedback']


def delay_samples(tau: float, dt: float) -> int:
    """Number of samples n with tau = n dt; raises ValueError if tau is not a multiple."""
    if not math.isfinite(tau) or tau < 0:
        raise ValueError(f'delay tau = {tau!r} s: must be finite and >= 0')
    n = round(tau / dt)
    if abs(n * dt - tau) > 1e-9 * max(1.0, tau) + 1e-12:
        raise ValueError(f'delay tau = {tau:g} s is not a multiple of the sample period '
                         f'{dt:g} s; allowed: n * {dt:g} s, e.g. {n * dt:g} s')
    return n


def gain_vector(gain) -> tuple[float, float, float, float]:
    """K as 4 finite floats on (x, theta, x', theta') [V/m, V/rad, V s/m, V s/rad], eq. (13); a 5th
    entry, on the bristle state z, is accepted only as 0 (z is not measured). ValueError otherwise,
    its message to be prefixed with the field's name."""
    expected = f'expected 4 finite numbers (x, theta, x\', theta\') [V/m, V/rad, V s/m, V s/rad], got {gain!r}'
    try:
        k = [float(v) for v in gain]
    except (TypeError, ValueError):
        raise ValueError(expected) from None
    if len(k) == 5 and k[4] != 0.0:
        raise ValueError(f'entry 4 (the bristle state z) must be 0: z is not measured; got {gain!r}')
    if len(k) not in (4, 5) or not all(math.isfinite(v) for v in k):
        raise ValueError(expected)
    return k[0], k[1], k[2], k[3]


@compiled
def filter_coefficient(cutoff_hz: float, dt: float) -> float:
    """Pole a of the first-order velocity filter v_k = a v_k-1 + (1 - a) raw_k (0 = no filter)."""
    if cutoff_hz <= 0:
        return 0.0
    return math.exp(-2 * math.pi * cutoff_hz * dt)


@compiled
def filtered_rate(a: float, rate: float, last: float, value: float, dt: float) -> float:
    """Next filtered velocity from the previous one and a backward difference."""
    return a * rate + (1 - a) * ((value - last) / dt)


@compiled
def feedback(gain, state, limit: float) -> float:
    """V = sat(K . s) [V], |V| <= ``limit``."""
    v = gain[0] * state[0] + gain[1] * state[1] + gain[2] * state[2] + gain[3] * state[3]
    return max(-limit, min(limit, v))


@dataclass(frozen=True)
class FeedbackSpec:
    """A :class:`StateFeedback` as numbers, what the compiled closed loop takes.

    gain : K (x, theta, x', theta') [V/m, V/rad, V s/m, V s/rad]
    control : (filter pole a, sample period [s], delay [samples], voltage limit [V])
    """

    gain: tuple
    control: tuple


class StateFeedback:
    """V_k = sat(K . (x, theta, x', theta')_{k-n}) with n = tau / dt.

    Parameters
    ----------
    gain : sequence of 4 (a 5th, z entry must be 0: z is not measured) [V/m, V/rad, V s/m, V s/rad]
    dt : sample period [s]
    delay : artificial feedback delay tau [s], a multiple of dt
    cutoff_hz : corner frequency of the velocity filter [Hz]; 0 = raw backward difference
    voltage_limit : |V| bound [V] (inf = none)

    Before the first sample the state is taken as constant at the first measurement
    with zero velocity, the history of paper eq. (30).
    """

    def __init__(self, gain, dt: float, delay: float = 0.0, cutoff_hz: float = 20.0,
                 voltage_limit: float = math.inf):
        try:
            self.gain = gain_vector(gain)
        except ValueError as exc:
            raise ValueError(f'gain: {exc}') from None
        if not dt > 0:
            raise ValueError(f'dt = {dt!r}: must be > 0')
        self.dt = dt
        self.cutoff_hz = float(cutoff_hz)
        self.voltage_limit = float(voltage_limit)
        self.set_delay(delay)
        self._last: tuple[float, float] | None = None
        self._vel = [0.0, 0.0]

    def set_delay(self, tau: float) -> None:
        """Change tau [s] (a multiple of dt); the history keeps what it has."""
        n = delay_samples(tau, self.dt)
        self.delay = tau
        old = list(getattr(self, '_history', []))
        self._depth = n + 1
        self._history = deque(old[-self._depth:], maxlen=self._depth)
        if old:
            while len(self._history) < self._depth:
                self._history.appendleft(self._history[0])

    @property
    def started(self) -> bool:
        """True once a measurement has been pushed (the filter and history hold state)."""
        return self._last is not None

    def loop_spec(self) -> FeedbackSpec:
        """The controller's settings as numbers (see :class:`FeedbackSpec`)."""
        return FeedbackSpec(gain=tuple(self.gain),
                            control=(filter_coefficient(self.cutoff_hz, self.dt), float(self.dt),
                                     float(self._depth - 1), float(self.voltage_limit)))

    def estimate(self, x: float, theta: float) -> tuple[float, float, float, float]:
        """Push one measurement; return the current state estimate."""
        if self._last is None:
            self._last = (x, theta)
            return (x, theta, 0.0, 0.0)
        a = filter_coefficient(self.cutoff_hz, self.dt)
        self._vel = [filtered_rate(a, self._vel[0], self._last[0], x, self.dt),
                     filtered_rate(a, self._vel[1], self._last[1], theta, self.dt)]
        self._last = (x, theta)
        return (x, theta, self._vel[0], self._vel[1])

    def update(self, x: float, theta: float) -> float:
        """Voltage [V] for the sample whose encoder readings are ``x`` [m], ``theta`` [rad]."""
        est = self.estimate(x, theta)
        if not self._history:
            self._history.extend([est] * self._depth)
        else:
            self._history.append(est)
        return feedback(self.gain, self._history[0], self.voltage_limit)
