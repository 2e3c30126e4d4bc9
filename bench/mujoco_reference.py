"""What a user would pick instead: the same closed loop in MuJoCo (PyPI ``mujoco``).

The cart-pendulum as MJCF: a slide joint for the cart (mass M), a hinge for a uniform rod
(mass m, length 2 l, inertia m l^2 / 3 about its centre), gravity g. The motor is
MuJoCo's ``dcmotor`` actuator driven by the voltage: with K = beta / alpha and
R = beta / alpha^2 its force K/R (V - K x') is the paper's eq. (2). The track friction is
the actuator's ``lugre`` friction (Coulomb mu_c F_N, static mu_s F_N, Stribeck velocity v_s,
the Gaussian Stribeck curve, i.e. gamma = 2) plus the viscous eps as actuator ``damping``:
sticking is approximated by a stiff bristle (``stiffness``, ``damping`` of the LuGre
model), not exact. The controller is the offline loop's own step
(``ipfric_core.physics.closedloop.controller_sample``: encoder, velocity filter, delay and
feedback) in a tight loop around ``mj_step`` at the sample rate, the plant stepping ``nstep``
Euler steps per sample.
"""
from __future__ import annotations

import math
from dataclasses import replace

import mujoco
import numpy as np

from ipfric_core.physics.closedloop import LS_PLANT, Trajectory, controller_sample, loop_start

MJCF = '''<mujoco model="ipfric cart-pendulum">
  <option timestep="{h}" gravity="0 0 -{g}" integrator="{integrator}"/>
  <worldbody>
    <body name="cart">
      <joint name="x" type="slide" axis="1 0 0"/>
      <inertial pos="0 0 0" mass="{M}" diaginertia="1e-3 1e-3 1e-3"/>
      <body name="rod">
        <joint name="theta" type="hinge" axis="0 1 0"/>
        <inertial pos="0 0 {l}" mass="{m}" diaginertia="{I} {I} 1e-9"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <dcmotor name="motor" joint="x" resistance="{R}" motorconst="{K} {K}" damping="{eps}"
             lugre="{sigma0} {sigma1} {Fc} {Fs} {vs}"/>
  </actuator>
</mujoco>'''


def model_xml(scenario, h: float, sigma0: float, integrator: str = 'Euler') -> str:
    """MJCF of the scenario's plant with plant step ``h`` [s] and bristle stiffness ``sigma0`` [N/m]."""
    p, f = scenario.plant, scenario.friction
    if f.model != 'exponential' or f.gamma != 2.0:
        raise ValueError('the MuJoCo reference models the exponential law with gamma = 2 only')
    fn = p.normal_force
    K = p.beta / p.alpha
    sigma1 = 2.0 * math.sqrt(sigma0 * (p.M + p.m))  # critically damped bristle
    return MJCF.format(h=h, g=p.g, integrator=integrator, M=p.M, m=p.m, l=p.l, I=p.m * p.l ** 2 / 3,
                       R=K / p.alpha, K=K, eps=f.eps, sigma0=sigma0, sigma1=sigma1, Fc=f.mu_c * fn,
                       Fs=f.mu_s * fn, vs=f.v_s)


class MujocoLoop:
    """A compiled MuJoCo model of a scenario, reusable for many runs."""

    def __init__(self, scenario, h: float = 1e-3, sigma0: float = 1e5, integrator: str = 'Euler'):
        self.scenario = scenario
        self.model = mujoco.MjModel.from_xml_string(model_xml(scenario, h, sigma0, integrator))
        self.data = mujoco.MjData(self.model)
        dt = scenario.sample_period
        self.nstep = max(1, round(dt / h))

    def run(self, duration: float, theta0: float | None = None, delay: float | None = None) -> Trajectory:
        s, c = self.scenario.sim, self.scenario.controller
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        d.qpos[1] = s.theta0 if theta0 is None else theta0
        dt = self.scenario.sample_period
        n = int(round(duration / dt)) + 1
        meas, state, volt = np.empty((n, 2)), np.empty((n, 4)), np.empty(n)
        # the controller of the offline loop (ipfric_core.physics.closedloop.controller_sample) on a loop
        # state whose plant entries are MuJoCo's
        scn = replace(self.scenario, sim=replace(s, theta0=float(d.qpos[1])))
        if delay is not None:
            scn = replace(scn, controller=replace(c, delay=delay))
        rig, ctrl = scn.make_rig().loop_spec(), scn.make_controller().loop_spec()
        z = loop_start(rig, ctrl)
        reason, k = 'duration', 0
        for k in range(n):
            q = d.qpos
            state[k, :2], state[k, 2:] = q, d.qvel
            z[LS_PLANT], z[LS_PLANT + 1] = q[0], q[1]
            mx, mth, v = controller_sample(rig.resolution, rig.sensors, ctrl.gain, ctrl.control, z)
            meas[k], volt[k] = (mx, mth), v
            if not (abs(q[1]) <= s.fallen_angle):
                reason = 'FALLEN'
                break
            if abs(q[0]) > s.track_limit:
                reason = 'TRACK_LIMIT'
                break
            d.ctrl[0] = v
            mujoco.mj_step(m, d, self.nstep)
        k += 1
        t = np.arange(k) * dt
        return Trajectory(t, state[:k], meas[:k], volt[:k], np.full(k, np.nan), np.zeros(k, bool), reason)
