"""controller_node: the state-feedback controller of the rig, paper eqs. (13) and (26).

Takes ``joint_states`` (sensor_msgs/JointState, encoder positions of ``cart`` and
``pendulum``), estimates velocities by a filtered difference, computes
V = sat(K (x, theta, x', theta')(t - tau)) with :class:`ipfric_core.physics.controller.StateFeedback`
and publishes ``voltage_command`` (ipfric_msgs/VoltageCommand) carrying the stamp and the
index of the measurement it was computed from (index = stamp / sample period). Under
``use_sim_time`` the command's header stamp is that simulated time too (the rig's time does
not move while the controller computes, in either time mode); otherwise the wall clock.

A rig's controller keeps its own rig: it obeys the joint states of one node only, ``rig_node``
(``sim_node`` in its namespace), recognised by the publisher of each message
(:class:`ipfric_ros.identity.Publishers`). Measurements of any other publisher are counted,
logged (once a second) and never obeyed; they cost a look-up each and cannot hold the loop.

The gain comes from the parameter file (``gain_source: yaml``) or is designed at start-up
by LQR on ``design_friction`` (``gain_source: design``). The gain used is logged and
published latched on ``controller_gain`` (std_msgs/Float64MultiArray), once ``rig_node``
publishes joint states and ``voltage_command`` is matched by ``min_command_subscribers``
subscriptions (2: the simulator and the recorder): the simulator waits for that message
before sample 0. ``delay``, ``gain``, ``cutoff_hz`` and ``voltage_limit`` can be changed at
run time (``delay 0``, an integer, is taken as 0.0 s); a delay that is not a multiple of the
sample period, or a gain that is not 4 finite numbers, is refused with the reason; each
change is logged with the first sample it applies to. A measurement with a NaN or infinite
position gets no command (the rig's watchdog then acts).

The loop waits on the joint-state subscription and the parameter services alone (a wait
set) and takes the measurements itself; an executor turn serves the services, the time
source and the rest when a request is there (the clock first, so that the parameter event is
stamped with the rig's current time) or once a second, after a command is out. (An executor turn
every 50 ms held one sample in 50 and put its latency in the 99th percentile.)
"""
from __future__ import annotations

import math
import sys
import time

from rcl_interfaces.msg import SetParametersResult
from rclpy.duration import Duration
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray

from ipfric_core.physics.closedloop import warm_up
from ipfric_core.physics.controller import delay_samples, gain_vector
from ipfric_core.physics.params import ConfigError
from ipfric_core.run.scenario import Scenario
from ipfric_msgs.msg import VoltageCommand
from ipfric_ros import topics
from ipfric_ros.identity import Publishers
from ipfric_ros.parameters import as_declared, check_unknown, declare, declare_scenario, plain
from ipfric_ros.rclpy_internals import SubscriptionWaiter
from ipfric_ros.realtime import LoopTuning, declare_tuning
from ipfric_ros.signals import StopRequest, node_process

#: Parameters that may change while the controller runs.
RUNTIME_PARAMETERS = ('delay', 'gain', 'cutoff_hz', 'voltage_limit')
#: [s] longest time between two executor turns (the time source's clock; a request is served at once)
TURN_EVERY_S = 1.0


class ControllerNode(Node):
    """StateFeedback behind ROS topics and parameters."""

    def __init__(self):
        super().__init__('controller_node', cli_args=topics.RIG_ARGUMENTS)
        read_only = set(Scenario.flat_defaults('controller_node')) - set(RUNTIME_PARAMETERS)
        self.scenario = declare_scenario(self, 'controller_node', read_only=read_only)
        self.min_subscribers = declare(
            self, 'controller_node', 'min_command_subscribers', 2,
            'publish controller_gain (ready) once voltage_command has this many subscriptions: the simulator '
            'and the recorder (1 to run without a recorder)', (1, 100), read_only=True)
        rig_node = declare(
            self, 'controller_node', 'rig_node', 'sim_node',
            'the node whose joint_states are obeyed (a name in this namespace, or fully qualified)',
            read_only=True)
        self.tuning = declare_tuning(self, 'controller_node')
        check_unknown(self, 'controller_node')

        c = self.scenario.controller
        self.period_ns = round(1e9 / c.sample_rate_hz)
        self.dt = 1.0 / c.sample_rate_hz
        self.controller = self.scenario.make_controller()
        warm_up(self.scenario)  # numba code loaded before sample 0, not during it
        how = 'from the parameter file' if c.gain_source == 'yaml' else (
            f'designed by LQR on the {c.design_friction.model} friction model, Q = {list(c.Q)}, R = {c.R:g}')
        if c.gain_source == 'design':  # let `gain` show the gain in use
            self.set_parameters([Parameter('gain', Parameter.Type.DOUBLE_ARRAY, list(self.controller.gain))])
        self.get_logger().info(
            f'gain K = {[round(k, 6) for k in self.controller.gain]} ({how}); delay {c.delay:g} s, '
            f'velocity filter {c.cutoff_hz:g} Hz, |V| <= {c.voltage_limit:g} V, {c.sample_rate_hz:g} Hz')

        self.add_pre_set_parameters_callback(lambda params: [as_declared(self, p) for p in params])
        self.add_on_set_parameters_callback(self._validate)
        self.add_post_set_parameters_callback(self._apply)
        self.pub_command = self.create_publisher(VoltageCommand, topics.VOLTAGE_COMMAND, topics.data_qos())
        self.pub_gain = self.create_publisher(Float64MultiArray, topics.CONTROLLER_GAIN, topics.latched_qos())
        self.sub_joints = self.create_subscription(JointState, topics.JOINT_STATES, lambda *_: None,
                                                   topics.data_qos(), callback_group=topics.OwnLoop())
        self.rig = Publishers(self, topics.JOINT_STATES, rig_node)
        self.sim_time = bool(self.get_parameter('use_sim_time').value)
        self.ready = False
        self.published = 0
        self.rejected = 0
        self.named: set[str] = set()    # strangers whose refused measurements were logged by name
        self.last_index = None
        self._names = None
        self._index = (0, 1)
        self._waiting_logged = 0.0

    # -- readiness -------------------------------------------------------------------------
    def _check_ready(self) -> bool:
        n = self.pub_command.get_subscription_count()
        rig = self.rig.present()
        if n < self.min_subscribers or not rig:
            now = time.monotonic()
            if now - self._waiting_logged > 5.0:
                self._waiting_logged = now
                self.get_logger().info(
                    f'waiting for {self.rig.expected} (joint_states publisher: {"yes" if rig else "no"}) and '
                    f'{self.min_subscribers} subscriptions of {self.pub_command.topic_name} (now {n}: the simulator '
                    f'and a recorder; -p min_command_subscribers:=1 runs without a recorder)')
            return False
        self.ready = True
        self._publish_gain()
        self.get_logger().info(f'ready: {self.rig.expected} publishes joint states, {self.pub_command.topic_name} '
                               f'matched by {n} subscription(s)')
        return True

    def _publish_gain(self) -> None:
        self.pub_gain.publish(Float64MultiArray(data=[float(k) for k in self.controller.gain]))

    # -- parameters ------------------------------------------------------------------------
    def _validate(self, params) -> SetParametersResult:
        for p in params:
            value = plain(p.value)
            if p.name == 'delay':
                try:
                    delay_samples(value, self.dt)
                except ValueError as exc:
                    return SetParametersResult(successful=False, reason=f'delay: {exc}')
            elif p.name == 'gain':
                try:
                    gain_vector(value)
                except ValueError as exc:
                    return SetParametersResult(successful=False, reason=f'gain: {exc}')
            elif p.name == 'cutoff_hz' and not (math.isfinite(value) and value >= 0.0):
                return SetParametersResult(successful=False, reason=f'cutoff_hz: {value!r} must be >= 0')
            elif p.name == 'voltage_limit' and not (value > 0.0):
                return SetParametersResult(successful=False, reason=f'voltage_limit: {value!r} must be > 0')
        return SetParametersResult(successful=True)

    def _apply(self, params) -> None:
        for p in params:
            value = plain(p.value)
            if p.name == 'delay':
                self.controller.set_delay(value)
            elif p.name == 'gain':
                self.controller.gain = gain_vector(value)
                if self.ready:
                    self._publish_gain()
            elif p.name == 'cutoff_hz':
                self.controller.cutoff_hz = float(value)
            elif p.name == 'voltage_limit':
                self.controller.voltage_limit = float(value)
            else:
                continue
            first = 'the first sample' if self.last_index is None else f'sample {self.last_index + 1}'
            self.get_logger().info(f'{p.name} set to {value} (from {first} on)')

    # -- control ---------------------------------------------------------------------------
    def on_joints(self, msg: JointState, gid: bytes) -> bool:
        """One measurement taken from the subscription; whether a command went out."""
        if not self.rig.accepts(gid):
            self.rejected += 1
            who = self.rig.strangers.get(gid, '?')
            text = (f'joint_states from {who}, not {self.rig.expected}: refused ({sum(self.rig.refused.values())} '
                    f'so far); the rig is controlled on its own measurements')
            if who != '?' and who not in self.named:     # each stranger named once, as soon as the graph knows it
                self.named.add(who)
                self.get_logger().error(text)
            else:
                self.get_logger().error(text, throttle_duration_sec=1.0)
            return False
        if not self.ready:
            return False
        names = tuple(msg.name)
        if names != self._names:
            try:
                self._index = tuple(names.index(j) for j in topics.JOINT_NAMES)
            except ValueError:
                self.rejected += 1
                self.get_logger().error(f'joint_states without joints {topics.JOINT_NAMES}: {names}',
                                        throttle_duration_sec=1.0)
                return False
            self._names = names
        try:
            x, theta = msg.position[self._index[0]], msg.position[self._index[1]]
        except IndexError:
            x = theta = math.nan
        stamp_ns = topics.stamp_to_ns(msg.header.stamp)
        k = round(stamp_ns / self.period_ns)
        if not (math.isfinite(x) and math.isfinite(theta)):
            self.rejected += 1
            self.get_logger().error(f'sample {k}: position not finite (x = {x}, theta = {theta}); no command',
                                    throttle_duration_sec=1.0)
            return False
        v = self.controller.update(x, theta)
        cmd = VoltageCommand(voltage=v, measurement_stamp=msg.header.stamp, sample_index=k)
        cmd.header.stamp = msg.header.stamp if self.sim_time else self.get_clock().now().to_msg()
        self.pub_command.publish(cmd)
        self.published += 1
        self.last_index = k
        return True

    def spin(self, stop: StopRequest) -> None:
        """The loop: measurements from the wait set, an executor turn for everything else."""
        executor = SingleThreadedExecutor()
        executor.add_node(self)
        waiter = SubscriptionWaiter(self, self.sub_joints, services=self.services)
        tuning = LoopTuning(self.tuning, self.get_logger())
        try:
            self._loop(stop, executor, waiter, tuning)
        finally:
            tuning.restore()

    def _loop(self, stop: StopRequest, executor, waiter, tuning: LoopTuning) -> None:
        next_turn = 0.0
        while not stop:
            if not self.ready and not self._check_ready():
                requests = waiter.wait(0.02)
            else:
                requests = waiter.wait(0.1)
            sent = False
            while (got := waiter.take()) is not None:
                sent = self.on_joints(*got) or sent
            if requests or time.monotonic() >= next_turn:
                for _ in range(4):   # the time source's clock first, then the requests (rclpy's order)
                    executor.spin_once(timeout_sec=0.0)
                next_turn = time.monotonic() + TURN_EVERY_S
            if sent:
                tuning.after_sample(self.published)

    def flush(self, timeout: float = 2.0) -> None:
        if not self.pub_command.wait_for_all_acked(Duration(seconds=timeout)):
            self.get_logger().warning(f'{topics.VOLTAGE_COMMAND}: not all commands acknowledged in {timeout:g} s')

    def report(self) -> str:
        strangers = ', '.join(f'{n} from {node}' for node, n in sorted(self.rig.refused.items()))
        return (f'published {self.published} commands (last sample {self.last_index}), rejected {self.rejected} '
                f'measurements' + (f' ({strangers})' if strangers else ''))


def main(args=None) -> int:
    with node_process('controller_node', args) as proc:
        try:
            node = proc.add(ControllerNode())
        except ConfigError as exc:
            proc.logger.fatal(f'configuration error: {exc}')
            return 2
        node.spin(proc.stop)
        node.flush()
        proc.logger.info(f'stopped by {proc.stop.reason}: {node.report()}')
        return 0


if __name__ == '__main__':
    sys.exit(main())
