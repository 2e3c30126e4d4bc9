"""sim_node: the simulated friction cart-pendulum rig.

Publishes, at every sample k (t_k = k / sample_rate_hz, simulated time), each topic in
the node's namespace (the rig's: ``/rig1/joint_states``, or ``/joint_states`` at the root):

- ``joint_states`` (sensor_msgs/JointState): encoder positions of ``cart`` [m] and
  ``pendulum`` [rad] quantized to the encoder resolution, no velocity, no effort (first,
  so that the controller starts at once),
- ``clock`` (rosgraph_msgs/Clock) = t_k: the rig's clock, which its nodes follow,
- ``plant_state`` (ipfric_msgs/PlantState): the ground truth,

and applies the ``voltage_command`` (ipfric_msgs/VoltageCommand) computed for sample k
over [t_k, t_k+1) (zero-order hold). ``time_mode``:

- ``lockstep``: sample k+1 is computed only after the command for sample k arrived:
  deterministic, faster than real time; the same sequence as
  :func:`ipfric_core.physics.closedloop.run_closed_loop`. An answer later than
  ``lockstep_timeout_s`` of wall time is waited for (logged and counted as late); only a
  controller silent for ``WATCHDOG_WALL_S`` (paused, gone) stalls the run.
- ``realtime``: sample k at wall time t0 + k dt; the latest command is held.

Safety (``safety_event``, ipfric_msgs/SafetyEvent): a NaN, infinite or out-of-range
command, a command for another sample (lockstep) or from another publisher than the
controller (the node ``controller_node`` of this namespace, recognised by the publisher of
each message, :class:`ipfric_ros.identity.Publishers`) gives 0 V and is counted
(BAD_COMMAND: the first of a burst at once, then one summary per second with counts); no
valid command for ``watchdog_samples`` samples, or for 2 s of wall time in lockstep,
gives 0 V (WATCHDOG, with STALL when the controller stopped answering); another node
publishing on a topic of the rig is named (INTRUDER). Commands
are taken with a deadline: a flood cannot hold a sample. The run ends on TRACK_LIMIT,
FALLEN, END (duration reached) or ABORT (SIGINT/SIGTERM/SIGHUP, or the supervisor gone),
announced as an event whose detail lists the messages published. Once a second the loop's
rate, stale samples and command latency go to ``diagnostics`` (diagnostic_msgs/DiagnosticArray).

Before sample 0 the node waits until the controller announced its gain and, with
``wait_for_recorder`` (the default), until a recorder subscribes to every topic it
publishes, so the bag holds the run from sample 0 whatever order the nodes start in.
All numerics live in ipfric_core (Scenario, Rig); this node adds topics and timing.
"""
from __future__ import annotations

import json
import sys
import time
from array import array
from collections import Counter
from dataclasses import replace

import numpy as np
from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rclpy.duration import Duration
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray

from ipfric_core.constants import ABORT, END, START
from ipfric_core.physics.closedloop import warm_up
from ipfric_core.physics.params import ConfigError
from ipfric_msgs.msg import PlantState, SafetyEvent, VoltageCommand
from ipfric_ros import topics
from ipfric_ros.identity import Publishers, node_of
from ipfric_ros.parameters import check_unknown, declare, declare_scenario
from ipfric_ros.rclpy_internals import SubscriptionWaiter, publisher_gid
from ipfric_ros.realtime import LoopTuning, declare_tuning
from ipfric_ros.signals import StopRequest, node_process

from .safety import BAD_COMMAND, WATCHDOG_WALL_S, CommandGuard, latency_summary

#: Most commands taken in one drain (a flood is cut into slices between samples).
DRAIN_MAX = 1000
#: [s] simulated time between two diagnostics messages (as many in lockstep as in realtime)
DIAGNOSTICS_EVERY_S = 1.0
#: [ns] one wait for acknowledgements between two executor turns at the end
ACK_SLICE_NS = 20_000_000


class StartError(RuntimeError):
    """The run could not start (peers not found in time)."""


class SimNode(Node):
    """The rig: a Scenario's Rig behind ROS topics."""

    def __init__(self, stop: StopRequest | None = None):
        super().__init__('sim_node', cli_args=topics.RIG_ARGUMENTS)
        self.stop = stop if stop is not None else StopRequest()
        self.scenario = declare_scenario(self, 'sim_node', read_only=True)
        self.wait_for_recorder = declare(
            self, 'sim_node', 'wait_for_recorder', True,
            'before sample 0, wait until a recorder subscribes to every published topic (false: run '
            'without a recorder)', read_only=True)
        self.wait_for_gain = declare(
            self, 'sim_node', 'wait_for_controller_gain', True,
            'before sample 0, wait for the controller_gain message (the controller is ready)',
            read_only=True)
        self.start_timeout = declare(
            self, 'sim_node', 'start_timeout_s', 60.0,
            'wall time to wait for the controller (and recorder) before giving up [s]', (0.0, 3600.0),
            read_only=True)
        self.result_file = declare(
            self, 'sim_node', 'result_file', '',
            'write the end reason and message counts of the run to this JSON file ("" = none)',
            read_only=True)
        controller = declare(
            self, 'sim_node', 'controller_node', 'controller_node',
            'the node whose voltage_command is obeyed (a name in this namespace, or fully qualified)',
            read_only=True)
        self.tuning = declare_tuning(self, 'sim_node')
        check_unknown(self, 'sim_node')

        s = self.scenario.sim
        self.settings = s
        self.rig = self.scenario.make_rig()
        warm_up(self.scenario)  # numba code loaded before sample 0, not during it
        self.period_ns = round(1e9 / s.sample_rate_hz)
        self.last_sample = round(s.duration * s.sample_rate_hz) if s.duration > 0 else None
        self.guard = CommandGuard(s.voltage_max, s.watchdog_samples)
        self.lockstep = s.time_mode == 'lockstep'
        self.diagnostics_every = max(100, round(DIAGNOSTICS_EVERY_S * s.sample_rate_hz / 100) * 100)

        qos = topics.data_qos()
        self.pub_joints = self.create_publisher(JointState, topics.JOINT_STATES, qos)
        self.pub_clock = self.create_publisher(Clock, topics.CLOCK, qos)
        self.pub_state = self.create_publisher(PlantState, topics.PLANT_STATE, qos)
        self.pub_event = self.create_publisher(SafetyEvent, topics.SAFETY_EVENT, topics.data_qos(100))
        self.pub_diagnostics = self.create_publisher(DiagnosticArray, topics.DIAGNOSTICS, topics.data_qos(10))
        self.sub_command = self.create_subscription(
            VoltageCommand, topics.VOLTAGE_COMMAND, lambda msg, info: self._on_command(msg, publisher_gid(info)), qos,
            callback_group=topics.OwnLoop())
        self.sub_gain = self.create_subscription(Float64MultiArray, topics.CONTROLLER_GAIN,
                                                 self._on_gain, topics.latched_qos())
        self.published: Counter[str] = Counter()  # fully qualified topic -> messages
        self.gain: list[float] | None = None
        self.controller = Publishers(self, topics.VOLTAGE_COMMAND, controller)
        self.intruders: dict[str, list[str]] = {}   # topic -> the other publishers' nodes
        self.late = 0               # lockstep: answers later than lockstep_timeout_s
        self.stalls = 0
        self._stalled = False
        self._last_valid = time.monotonic()
        self._sent_at = array('d')  # [s] monotonic time measurement k was published, at index k
        self.latency = array('d')   # [s] from publishing a measurement to taking its command
        self._waiting_for = -1      # lockstep: sample whose command is awaited
        self._command = None        # lockstep: its voltage; realtime: latest unused voltage
        self._executor = SingleThreadedExecutor()
        self._executor.add_node(self)
        self._commands = SubscriptionWaiter(self, self.sub_command)
        self._diagnosed = (0.0, 0, 0, 0)   # (wall time, sample, stale samples, latencies) at the last diagnostics
        self.get_logger().info(
            f'{s.time_mode} at {s.sample_rate_hz:g} Hz, duration {s.duration:g} s, theta0 {s.theta0:g} rad, '
            f'friction {self.scenario.friction.model}; encoder {s.cart_resolution:g} m, '
            f'{s.angle_resolution:g} rad')

    # -- subscriptions ---------------------------------------------------------------------
    def _on_command(self, msg: VoltageCommand, gid: bytes) -> None:
        if not self.controller.accepts(gid):
            self._refuse('unexpected publisher', f'a command from {self.controller.strangers.get(gid, "?")}, '
                                                 f'not {self.controller.expected}')
            return
        if self.lockstep and msg.sample_index != self._waiting_for:
            self._refuse('wrong sample index', f'a command for sample {msg.sample_index} while waiting for '
                                               f'sample {self._waiting_for}')
            return
        self._command = msg.voltage
        if 0 <= msg.sample_index < len(self._sent_at):
            self.latency.append(time.monotonic() - self._sent_at[msg.sample_index])

    def _refuse(self, kind: str, detail: str) -> None:
        first = self.guard.refusals.note(kind, detail, self.rig.k, time.monotonic())
        if first:
            self.event(BAD_COMMAND, first)

    def _on_gain(self, msg: Float64MultiArray) -> None:
        self.gain = list(msg.data)
        self.get_logger().info(f'controller gain {self.gain}')

    # -- publishing ------------------------------------------------------------------------
    def _stamp(self, k: int) -> Time:
        return topics.stamp_of_sample(k, self.period_ns)

    def _publish_sample(self) -> None:
        """Publish /clock, joint_states and plant_state of the current sample."""
        rig, k = self.rig, self.rig.k
        stamp = self._stamp(k)
        x, theta = rig.measure()
        js = JointState(name=list(topics.JOINT_NAMES), position=[x, theta])
        js.header.stamp = stamp
        self.pub_joints.publish(js)
        self._sent_at.append(time.monotonic())
        self.pub_clock.publish(Clock(clock=stamp))
        tr = rig.truth()
        ps = PlantState(x=tr['x'], theta=tr['theta'], x_dot=tr['x_dot'], theta_dot=tr['theta_dot'],
                        friction_force=tr['friction_force'], z=tr['z'], stuck=bool(tr['stuck']),
                        voltage_applied=tr['voltage_applied'], sample_index=k)
        ps.header.stamp = stamp
        self.pub_state.publish(ps)
        self.published[self.pub_clock.topic_name] += 1
        self.published[self.pub_joints.topic_name] += 1
        self.published[self.pub_state.topic_name] += 1

    def event(self, code: str, detail: str) -> None:
        k = self.rig.k
        msg = SafetyEvent(code=code, detail=detail, sample_index=k)
        msg.header.stamp = self._stamp(k)
        self.pub_event.publish(msg)
        self.published[self.pub_event.topic_name] += 1
        text = f'{code} at sample {k} (t = {k * self.period_ns * 1e-9:.3f} s): {detail}'
        if code in (START, END):
            self.get_logger().info(text)
        else:  # (rclpy wants one severity per call site)
            self.get_logger().warning(text)

    def _apply(self, command) -> float:
        now = time.monotonic()
        v, events = self.guard.apply(command, self.rig.k, now)
        if self.guard.missed == 0:          # a valid command
            self._last_valid, self._stalled = now, False
        for code, detail in events:
            self.event(code, detail)
        summary = self.guard.refusals.report(now)
        if summary:
            self.event(BAD_COMMAND, summary)
        return v

    def _check_intruders(self, final: bool = False) -> None:
        """Name the nodes publishing on a topic of the rig besides the expected one (once per node).
        A publisher the graph cannot name yet is named when it can; at the end (``final``) as '?'."""
        me = f'{self.get_namespace().rstrip("/")}/{self.get_name()}'
        for pub, owner in ((self.sub_command, self.controller.expected), (self.pub_joints, me), (self.pub_state, me),
                           (self.pub_clock, me)):
            topic = pub.topic_name
            others = [node_of(i) for i in self.get_publishers_info_by_topic(topic)]
            if owner in others:
                others.remove(owner)
            seen = self.intruders.setdefault(topic, [])
            new = sorted({n for n in others if n not in seen and (n != '?' or final and len(seen) < len(others))})
            if new:
                seen.extend(new)
                self.event(SafetyEvent.INTRUDER,
                           f'{len(others) + 1} publishers on {topic}, expected {owner} alone; also {", ".join(new)}: '
                           f'their messages are refused (commands) or ignored by the controller (measurements)')
        self.intruders = {t: n for t, n in self.intruders.items() if n}

    # -- start -----------------------------------------------------------------------------
    @property
    def recorded_publishers(self) -> tuple:
        """The publishers of the topics a run's recorder records: it is waited for on each before sample 0,
        and each one's messages acknowledged at the end (:meth:`flush_end`)."""
        return self.pub_event, self.pub_joints, self.pub_state, self.pub_clock, self.pub_diagnostics

    def _missing_peers(self) -> list[str]:
        rec = 1 if self.wait_for_recorder else 0
        need = [(pub, rec + (pub is self.pub_joints)) for pub in self.recorded_publishers]   # and the controller
        missing = [f'{pub.topic_name}: {pub.get_subscription_count()}/{n} subscribers'
                   for pub, n in need if pub.get_subscription_count() < n]
        if not self.controller.present():
            missing.append(f'{self.sub_command.topic_name}: no publisher of {self.controller.expected}')
        if self.wait_for_gain and self.gain is None:
            missing.append(f'{self.sub_gain.topic_name}: not received')
        return missing

    def wait_for_peers(self) -> bool:
        """Spin until the controller (and recorder) are matched; False if stopped first."""
        t0 = logged = time.monotonic()
        while True:
            missing = self._missing_peers()
            if not missing:
                self.get_logger().info(f'peers matched after {time.monotonic() - t0:.2f} s')
                return True
            if self.stop:
                return False
            now = time.monotonic()
            if now - t0 > self.start_timeout:
                raise StartError(f'peers not matched after {self.start_timeout:g} s: ' + '; '.join(missing))
            if now - logged > 5.0:
                logged = now
                self.get_logger().info('waiting for ' + '; '.join(missing) + (
                    ' (a recorder records from sample 0; -p wait_for_recorder:=false runs without one)'
                    if self.wait_for_recorder else ''))
            self._executor.spin_once(timeout_sec=0.05)

    # -- loops -----------------------------------------------------------------------------
    def _end_check(self, limit):
        if self.stop:
            return ABORT, f'stopped by {self.stop.reason}'
        if limit:
            return limit
        if self.last_sample is not None and self.rig.k >= self.last_sample:
            return END, f'duration {self.settings.duration:g} s reached'
        return None

    def _take_commands(self, timeout: float) -> None:
        """Lockstep hot path: wait up to ``timeout`` s on the command subscription alone, take
        what arrived. Cheaper than an executor turn, which waits on every entity of the node
        (parameter services included); those are served by an executor turn every 100 samples.
        The drain stops after ``DRAIN_MAX`` messages or ``timeout`` + 2 ms, whichever first, so
        that a flood cannot hold the sample.
        """
        self._commands.wait(timeout)
        end = time.monotonic() + timeout + 0.002
        for _ in range(DRAIN_MAX):
            got = self._commands.take()
            if got is None:
                return
            self._on_command(*got)
            if self._command is not None or time.monotonic() > end:
                return

    def _await_command(self, k: int):
        """Lockstep: wait until the command for sample k arrives. A late answer (later than
        ``lockstep_timeout_s``) is waited for and counted; None only when the controller stalled
        (no valid command for WATCHDOG_WALL_S), is gone, or the run is stopped."""
        self._waiting_for, self._command = k, None
        if k % 100 == 0:
            self._serve()
        self._take_commands(0.0)
        if self._command is not None or self.guard.tripped:
            # with the watchdog tripped (0 V held) the rig runs on, taking a command if one is there
            return self._command
        t0 = time.monotonic()
        late_at = t0 + self.settings.lockstep_timeout_s
        counted = False
        while self._command is None and not self.stop:
            now = time.monotonic()
            if now - self._last_valid >= WATCHDOG_WALL_S:
                self._stall(k, now)
                break
            if not counted and now >= late_at:
                counted = True
                self.late += 1
                self.get_logger().warning(f'the command for sample {k} is later than '
                                          f'{self.settings.lockstep_timeout_s:g} s of wall time; waiting for it '
                                          f'({self.late} late so far)',
                                          throttle_duration_sec=1.0)
            if now - t0 > 0.02 and self.sub_command.get_publisher_count() == 0:
                self.get_logger().warning(f'no command publisher (sample {k})', throttle_duration_sec=1.0)
                break
            self._take_commands(0.02)
        return self._command

    def _serve(self) -> None:
        """Every 100 samples an executor turn (parameter services, the gain); every second of
        simulated time the graph checked for intruders and the diagnostics (graph queries take
        a fraction of a sample: rare enough to stay out of the latency's 99th percentile)."""
        self._executor.spin_once(timeout_sec=0.0)
        if self.rig.k % self.diagnostics_every == 0:
            self._check_intruders()
            if self.rig.k:
                self._diagnose(time.monotonic())

    def _diagnose(self, now: float) -> None:
        """diagnostic_msgs/DiagnosticArray of the loop since the last one: rate, stale samples, latency."""
        t, k, stale, n_lat = self._diagnosed
        self._diagnosed = (now, self.rig.k, self.guard.missing, len(self.latency))
        lat = latency_summary(np.frombuffer(self.latency, dtype=float)[n_lat:])
        samples = self.rig.k - k
        level, message = DiagnosticStatus.OK, 'on time'
        if self.guard.tripped or self._stalled:
            level, message = DiagnosticStatus.ERROR, 'watchdog: 0 V applied'
        elif self.guard.missing - stale or self.intruders:
            level, message = DiagnosticStatus.WARN, 'stale samples' if self.guard.missing - stale else 'intruders'
        values = {'time_mode': self.settings.time_mode, 'sample': self.rig.k,
                  'rate_hz': f'{samples / max(now - t, 1e-9):.1f}', 'stale_samples': self.guard.missing - stale,
                  'stale_samples_total': self.guard.missing, 'late_answers_total': self.late,
                  'commands_refused_total': self.guard.refused,
                  'intruders': ', '.join(n for nodes in self.intruders.values() for n in nodes)}
        values.update({f'latency_{k}_ms': f'{v * 1e3:.3f}' for k, v in lat.items() if k != 'commands'})
        status = DiagnosticStatus(level=level, name=f'{self.get_fully_qualified_name()}: loop', message=message,
                                  hardware_id=self.get_namespace(),
                                  values=[KeyValue(key=k, value=str(v)) for k, v in values.items()])
        msg = DiagnosticArray(status=[status])
        msg.header.stamp = self._stamp(self.rig.k)
        self.pub_diagnostics.publish(msg)
        self.published[self.pub_diagnostics.topic_name] += 1

    def _chores(self, tuning: LoopTuning) -> bool:
        """Realtime: what a sample needs besides its loop, done in its slack; False (done)."""
        if self.rig.k % 100 == 0:
            self._serve()
        tuning.after_sample(self.rig.k)
        return False

    def _stall(self, k: int, now: float) -> None:
        """No valid command for WATCHDOG_WALL_S of wall time: STALL once per episode, watchdog."""
        if not self._stalled:
            self._stalled = True
            self.stalls += 1
            self.event(SafetyEvent.STALL, f'no valid command for {now - self._last_valid:.2f} s of wall time '
                                          f'(sample {k}): the controller is paused or gone')
        ev = self.guard.trip(f'no valid command for {WATCHDOG_WALL_S:g} s of wall time')
        if ev:
            self.event(*ev)

    def run_lockstep(self, tuning: LoopTuning):
        while True:
            self._publish_sample()
            limit = self.rig.limit_violation()
            v = self._apply(self._await_command(self.rig.k))
            end = self._end_check(limit)
            if end:
                return end
            self.rig.step(v)
            tuning.after_sample(self.rig.k)

    def run_realtime(self, tuning: LoopTuning):
        """Sample k at wall time t0 + k dt; the latest command that arrived is held (ZOH).

        A command computed from sample k arrives during [t_k, t_k+1) and is applied from
        t_k+1 on, as on the real rig. Between samples the loop waits on the command
        subscription until the next deadline; a late sample is taken at once (catching up).
        Its chores (an executor turn every 100 samples, the garbage collector's) wait until the
        sample's command is in, so that they never delay taking it.
        """
        period = self.period_ns * 1e-9
        t0 = time.monotonic()
        late = 0
        while True:
            command, self._command = self._command, None
            v = self._apply(command)
            self._publish_sample()
            end = self._end_check(self.rig.limit_violation())
            if end:
                if late:
                    self.get_logger().warning(f'{late} samples started more than one period late')
                return end
            self.rig.step(v)
            chores = True       # executor turn, garbage: once this sample's command is in (off its latency)
            deadline = t0 + self.rig.k * period
            now = time.monotonic()
            if now > deadline + period:
                late += 1
            while now < deadline and not self.stop:
                self._take_commands(deadline - now)
                if chores and self._command is not None:
                    chores = self._chores(tuning)
                now = time.monotonic()
            self._take_commands(0.0)
            if chores:
                self._chores(tuning)

    def run(self) -> int:
        """Wait for peers, run to the end, announce it; the process exit code."""
        if not self.wait_for_peers():
            self.get_logger().info(f'stopped by {self.stop.reason} before the start')
            return 0
        tuning = LoopTuning(self.tuning if not self.lockstep else replace(self.tuning, realtime_priority=0, cpu=-1),
                            self.get_logger())
        self.event(START, f'{self.settings.time_mode} run of {self.settings.duration:g} s, '
                            f'friction {self.scenario.friction.model}, theta0 {self.settings.theta0:g} rad'
                            + (f', gain {self.gain}' if self.gain else ''))
        t0 = self._last_valid = time.monotonic()
        self._diagnosed = (t0, 0, 0, 0)
        try:
            code, detail = self.run_lockstep(tuning) if self.lockstep else self.run_realtime(tuning)
        finally:
            tuning.restore()
        wall = time.monotonic() - t0
        self._check_intruders(final=True)
        summary = self.guard.refusals.report(time.monotonic(), force=True)
        if summary:
            self.event(BAD_COMMAND, summary)
        samples = self.rig.k + 1
        self.published[self.pub_event.topic_name] += 1  # the event below
        counts = dict(sorted(self.published.items()))
        self.published[self.pub_event.topic_name] -= 1
        self.event(code, f'{detail}; samples {samples}; published {json.dumps(counts)}')
        self.flush_end()
        result = {
            'end_reason': code, 'detail': detail, 'samples': samples, 'last_sample': self.rig.k,
            'stopped_by': self.stop.reason, 'namespace': self.get_namespace(),
            'sim_time_s': self.rig.k * self.period_ns * 1e-9, 'wall_time_s': wall,
            'steps_per_s': samples / wall if wall > 0 else None, 'published': dict(self.published),
            'commands_refused': self.guard.refused, 'refused_by_kind': dict(self.guard.refusals.total),
            'refused_by_publisher': dict(self.controller.refused),
            'samples_without_command': self.guard.missing, 'late_answers': self.late,
            'watchdog_trips': self.guard.trips, 'stalls': self.stalls, 'intruders': self.intruders,
            'command_latency_s': latency_summary(np.frombuffer(self.latency, dtype=float)),
            'time_mode': self.settings.time_mode, 'gain': self.gain, 'tuning': tuning.applied,
        }
        self.get_logger().info(f'run ended: {code} ({detail}); {samples} samples in {wall:.2f} s wall '
                               f'({result["steps_per_s"]:.0f} samples/s); published {counts}')
        if self.result_file:
            with open(self.result_file, 'w') as f:
                json.dump(result, f, indent=2)
        self.serve_pending()
        return 0

    def flush_end(self, timeout: float = 5.0) -> None:
        """Wait until every subscriber acknowledged what was published (reliable QoS), ``timeout``
        [s] in all, serving the parameter services meanwhile (a request is answered, not left
        hanging); once a publisher times out (a subscriber gone without a goodbye, e.g. a
        killed recorder) the others are not waited for.
        """
        deadline = time.monotonic() + timeout
        for pub in self.recorded_publishers:
            while not pub.wait_for_all_acked(Duration(nanoseconds=ACK_SLICE_NS)):
                self._executor.spin_once(timeout_sec=0.0)
                if time.monotonic() > deadline:
                    self.get_logger().warning(f'{pub.topic_name}: not all messages acknowledged within '
                                              f'{timeout:g} s; not waiting further')
                    return

    def serve_pending(self) -> None:
        """Answer every request already received (e.g. a ``ros2 param set`` sent as the run
        ended) before the services go away with the node."""
        for _ in range(10):
            self._executor.spin_once(timeout_sec=0.0)


def main(args=None) -> int:
    with node_process('sim_node', args) as proc:
        logger, node = proc.logger, None
        try:
            node = proc.add(SimNode(proc.stop))
            return node.run()
        except ConfigError as exc:
            logger.fatal(f'configuration error: {exc}')
            return 2
        except StartError as exc:
            logger.fatal(str(exc))
            if node is not None:
                node.event(ABORT, str(exc))
                node.flush_end(1.0)
            return 1
        except Exception as exc:  # an internal error still ends the run with a reason
            logger.fatal(f'internal error: {type(exc).__name__}: {exc}')
            if node is not None:
                try:
                    node.event(ABORT, f'internal error: {type(exc).__name__}: {exc}')
                    node.flush_end(1.0)
                except Exception:
                    pass
            raise


if __name__ == '__main__':
    sys.exit(main())
