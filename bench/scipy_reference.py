"""The accuracy reference: the closed loop with the plant integrated by scipy's solve_ivp.

LSODA between events (rtol 1e-10, atol 1e-12); the stop of a sliding cart (x' = 0) and the
breakaway of a stuck one (|held force| = mu_s F_N) are terminal events located by
solve_ivp. A drive with play adds the motor side (its offset from the cart and its speed) to the
state, coupled to the cart by its contact force in every phase. The equations are ipfric's own
(``plant.rates``, ``plant.held_force``, ``friction.holds``, ``plant.drive_contact_force``): the
reference checks the integration, not the model. Everything around the plant (encoders,
controller, rig effects) is the python engine's.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from ipfric_core.physics.closedloop import run_closed_loop
from ipfric_core.physics.friction import holds, static_limit, sticks
from ipfric_core.physics.plant import drive_contact_force, force_input, rates, stuck_theta_acceleration
from ipfric_core.physics.simulate import NO_DRIVE, friction_now, held

RTOL, ATOL = 1e-10, 1e-12


class ScipySimulator:
    """Drop-in for :class:`ipfric_core.physics.simulate.Simulator` (state, stuck, t, step, friction_force)."""

    def __init__(self, model, state0, extra_force, drive=NO_DRIVE):
        self.pp, self.fp, self.ef = model.vector, model.friction.vector, extra_force
        self.n = model.n_states
        self.y = np.zeros(7)          # (x, theta, x', theta', z, motor side minus cart, motor side's speed)
        self.y[:len(state0)] = state0
        self.dp = tuple(float(v) for v in drive)
        if self.dp[0] > 0.0:          # the cart takes the contact's force in the motor's place
            self.pp = force_input(self.pp)
            self.motor = model.vector
        self.stuck, self.d, self.t = False, 0.0, 0.0
        self.hybrid = sticks(self.fp)
        self.lim = static_limit(self.fp)

    @property
    def state(self) -> list:
        return list(self.y[:self.n])

    def friction_force(self, voltage: float) -> float:
        return friction_now(self.pp, self.fp, self.ef, tuple(self.y[:5]), (float(self.stuck), self.d, 0.0),
                            self._force(self.y, voltage))

    def _force(self, y, voltage):
        """The force on the cart in the motor's place: the voltage, or a drive's contact [N]."""
        return drive_contact_force(self.dp, y[5], y[6] - y[2]) if self.dp[0] > 0.0 else voltage

    def _held(self, y, voltage):
        return held(self.pp, self.ef, tuple(y[:5]), self._force(y, voltage))

    def _motor_side(self, y, voltage):
        """(d', vb') of a drive's motor side: mass vb' = alpha V - beta vb - contact force (eq. 2)."""
        if self.dp[0] <= 0.0:
            return 0.0, 0.0
        alpha, beta = self.motor[4], self.motor[5]
        return y[6] - y[2], (alpha * voltage - beta * y[6] - self._force(y, voltage)) / self.dp[1]

    def _slide(self, t0, t1, voltage, with_event):
        pp, fp, ef, d = self.pp, self.fp, self.ef, self.d

        def stop(t, y):     # positive at the start (a cart set sliding from rest starts at x' = 0)
            return y[2] * d if t > t0 else 1.0

        def rhs(t, y):
            return (*rates(pp, fp, ef, tuple(y[:5]), self._force(y, voltage), d), *self._motor_side(y, voltage))
        stop.terminal, stop.direction = True, -1
        return solve_ivp(rhs, (t0, t1), self.y, method='LSODA', rtol=RTOL, atol=ATOL,
                         events=stop if with_event else None)

    def _swing(self, t0, t1, voltage):
        """The stuck cart: the pendulum, and a drive's motor side against the resting cart."""
        pp, y0 = self.pp, self.y.copy()

        def full(y):
            return np.array([y0[0], y[0], 0.0, y[1], y0[4], y[2], y[3]])

        def breakaway(t, y):
            return abs(self._held(full(y), voltage)) - self.lim

        def rhs(t, y):
            return (y[1], stuck_theta_acceleration(pp, y[0]), *self._motor_side(full(y), voltage))
        breakaway.terminal, breakaway.direction = True, 1
        return solve_ivp(rhs, (t0, t1), y0[[1, 3, 5, 6]], method='LSODA', rtol=RTOL, atol=ATOL, events=breakaway)

    def step(self, voltage: float, dt: float) -> None:
        t, end = 0.0, dt
        for _ in range(1000):
            if end - t <= 1e-15:
                break
            if not self.hybrid:
                self.y = self._slide(t, end, voltage, False).y[:, -1]
                break
            if self.stuck:
                applied = self._held(self.y, voltage)
                if not holds(self.fp, applied):
                    self.stuck, self.d = False, math.copysign(1.0, applied)
                    continue
                sol = self._swing(t, end, voltage)
                self.y[1], self.y[3], self.y[5], self.y[6] = sol.y[:, -1]
                t = sol.t[-1]
                if sol.status == 1:  # broke away
                    self.stuck, self.d = False, math.copysign(1.0, self._held(self.y, voltage))
                continue
            if self.d == 0.0:
                if self.y[2] != 0.0:
                    self.d = math.copysign(1.0, self.y[2])
                    continue
            else:
                sol = self._slide(t, end, voltage, True)
                self.y, t = sol.y[:, -1].copy(), sol.t[-1]
                if sol.status != 1:
                    continue
                self.y[2] = 0.0
            applied = self._held(self.y, voltage)   # at rest: stick, or slide along the force
            if holds(self.fp, applied):
                self.stuck, self.d = True, 0.0
            else:
                self.d = math.copysign(1.0, applied)
        self.t += dt


def run_scipy(scenario, duration: float):
    """The scenario's closed loop with the plant integrated by :class:`ScipySimulator`."""
    rig = scenario.make_rig()
    s = scenario.sim
    rig.sim = ScipySimulator(rig.sim.model, [0.0, s.theta0, 0.0, 0.0], scenario.truth.force_vector())
    return run_closed_loop(rig, scenario.make_controller(), duration, engine='python')
