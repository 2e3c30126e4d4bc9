"""Time integration of the nonlinear cart-pendulum with exact stick-slip.

:class:`Simulator` advances the plant over one sample with the voltage held constant
(zero-order hold). Smooth laws are integrated with classical RK4 substeps. A sticking
law (coulomb, exponential without smoothing) is integrated as a hybrid system:

- sliding: RK4 with sgn(x') fixed to the direction of motion; when x' reaches zero
  inside a substep the crossing instant is located (Brent's method on the RK4 step
  length), the state is placed there with x' = 0, and the cart sticks if static
  friction can hold it (``Friction.holds`` on ``CartPendulum.held_force``, which
  includes the pendulum's reaction), otherwise it slides the other way;
- stuck: x, x' are frozen, the pendulum swings with theta'' = 3 g sin(theta)/(4 l); the
  breakaway instant where |held force| reaches mu_s F_N is located the same way.

Events are located, never stepped over, so the motion neither chatters around v = 0
nor stalls.
"""
from __future__ import annotations

import math
from typing import Callable

from scipy.optimize import brentq

from .plant import CartPendulum

ExtraForce = Callable[[float, float], float]


class Simulator:
    """Stateful integrator of one plant.

    Parameters
    ----------
    model : CartPendulum
    state0 : sequence
        Initial (x, theta, x', theta'[, z]) [SI]; missing z defaults to 0.
    substep : float
        Largest RK4 step [s] (default 0.25 ms, four per 1 kHz sample).
    extra_force : callable(x, x') -> N, optional
        A force on the cart the friction model does not know (e.g. cogging).
    """

    MAX_EVENTS = 64  # per substep; a guard, never reached in normal motion

    def __init__(self, model: CartPendulum, state0, substep: float = 2.5e-4,
                 extra_force: ExtraForce | None = None):
        self.model = model
        s = [float(v) for v in state0]
        s += [0.0] * (model.n_states - len(s))
        self.state = s[:model.n_states]
        self.t = 0.0
        self.substep = float(substep)
        self.extra_force = extra_force
        self.stuck = False
        self.direction = 0.0  # sign of motion used by a sticking law while sliding
        self.events = 0  # number of stick/slip transitions so far

    # -- forces -----------------------------------------------------------------
    def _extra(self, s) -> float:
        return self.extra_force(s[0], s[2]) if self.extra_force else 0.0

    def held_force(self, s, voltage: float) -> float:
        """Force static friction must cancel at rest [N] (with x' = 0)."""
        m = self.model
        return m.held_force(s[1], s[3], m.motor_force(voltage, 0.0) + self._extra(s))

    def friction_force(self, voltage: float) -> float:
        """Friction force on the cart in the current state [N]."""
        s = self.state
        if self.stuck:
            return -self.held_force(s, voltage)
        z = s[4] if len(s) == 5 else 0.0
        return self.model.friction.force(s[2], z, self.direction)

    # -- single steps -----------------------------------------------------------
    def _rk4_slide(self, s, h, voltage):
        m, d = self.model, self.direction
        if self.extra_force:
            def f(y):
                return m.derivative(y, voltage, d, self.extra_force(y[0], y[2]))
        else:
            def f(y):
                return m.derivative(y, voltage, d)
        k1 = f(s)
        k2 = f([a + 0.5 * h * b for a, b in zip(s, k1)])
        k3 = f([a + 0.5 * h * b for a, b in zip(s, k2)])
        k4 = f([a + h * b for a, b in zip(s, k3)])
        return [a + h / 6.0 * (b1 + 2 * b2 + 2 * b3 + b4)
                for a, b1, b2, b3, b4 in zip(s, k1, k2, k3, k4)]

    def _rk4_stuck(self, s, h):
        acc = self.model.stuck_theta_acceleration
        th, w = s[1], s[3]
        k1t, k1w = w, acc(th)
        k2t, k2w = w + 0.5 * h * k1w, acc(th + 0.5 * h * k1t)
        k3t, k3w = w + 0.5 * h * k2w, acc(th + 0.5 * h * k2t)
        k4t, k4w = w + h * k3w, acc(th + h * k3t)
        out = list(s)
        out[1] = th + h / 6.0 * (k1t + 2 * k2t + 2 * k3t + k4t)
        out[3] = w + h / 6.0 * (k1w + 2 * k2w + 2 * k3w + k4w)
        out[2] = 0.0
        return out

    def _settle_at_rest(self, voltage: float) -> None:
        """At x' = 0: stick if static friction holds, else slide along the held force."""
        applied = self.held_force(self.state, voltage)
        if self.model.friction.holds(applied):
            self.stuck, self.direction = True, 0.0
            self.state[2] = 0.0
        else:
            self.stuck, self.direction = False, math.copysign(1.0, applied)
        self.events += 1

    def _advance_hybrid(self, h: float, voltage: float) -> None:
        fr = self.model.friction
        remaining = h
        for _ in range(self.MAX_EVENTS):
            if remaining <= 0.0:
                return
            s = self.state
            if self.stuck:
                if not fr.holds(self.held_force(s, voltage)):
                    self.stuck = False
                    self.direction = math.copysign(1.0, self.held_force(s, voltage))
                    self.events += 1
                    continue
                new = self._rk4_stuck(s, remaining)
                if fr.holds(self.held_force(new, voltage)):
                    self.state = new
                    return
                lim = fr.static_limit

                def excess(tau):
                    return abs(self.held_force(self._rk4_stuck(s, tau), voltage)) - lim
                tb = brentq(excess, 0.0, remaining, xtol=1e-13)
                tb = min(remaining, tb * (1 + 1e-9) + 1e-15)  # step just past the threshold
                self.state = self._rk4_stuck(s, tb)
                remaining -= tb
                self.stuck = False
                self.direction = math.copysign(1.0, self.held_force(self.state, voltage))
                self.events += 1
                continue
            if self.direction == 0.0:
                if s[2] == 0.0:
                    self._settle_at_rest(voltage)
                    continue
                self.direction = math.copysign(1.0, s[2])
            new = self._rk4_slide(s, remaining, voltage)
            if new[2] * self.direction > 0.0:
                self.state = new
                return
            d = self.direction
            start = max(abs(s[2]), 1e-300)  # the motion starts along d by construction
            tc = brentq(lambda tau: self._rk4_slide(s, tau, voltage)[2] * d if tau > 0 else start,
                        0.0, remaining, xtol=1e-13)
            self.state = self._rk4_slide(s, tc, voltage)
            self.state[2] = 0.0
            remaining -= tc
            self._settle_at_rest(voltage)
        # Guard (more than MAX_EVENTS transitions in one substep): finish it sliding.
        self.state = self._rk4_slide(self.state, remaining, voltage)

    def step(self, voltage: float, dt: float) -> None:
        """Advance by ``dt`` [s] with the voltage held at ``voltage`` [V]."""
        n = max(1, math.ceil(dt / self.substep - 1e-9))
        h = dt / n
        hybrid = self.model.friction.sticks
        for _ in range(n):
            if hybrid:
                self._advance_hybrid(h, voltage)
            else:
                self.state = self._rk4_slide(self.state, h, voltage)
        self.t += dt
