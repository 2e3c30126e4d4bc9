"""controller_node: the state-feedback controller of the rig, paper eqs. (13) and (26).

Subscribes ``joint_states`` (sensor_msgs/JointState, encoder positions of ``cart`` and
``pendulum``), estimates velocities by a filtered difference, computes
V = sat(K (x, theta, x', theta')(t - tau)) with :class:`ipfric_core.physics.controller.StateFeedback`
and publishes ``voltage_command`` (ipfric_msgs/VoltageCommand) carrying the stamp and the
index of the measurement it was computed from (index = stamp / sample period).

The gain comes from the parameter file (``gain_source: yaml``) or is designed at start-up
by LQR on ``design_friction`` (``gain_source: design``). The gain used is logged and
published latched on ``controller_gain`` (std_msgs/Float64MultiArray), once the command
publisher is matched by ``min_command_subscribers`` subscriptions: the simulator waits for
that message before sample 0. ``delay``, ``gain``, ``cutoff_hz`` and ``voltage_limit`` can be
changed at run time; a delay that is not a multiple of the sample period, or a gain that is
not 4 finite numbers, is refused with the reason. A measurement with a NaN or infinite
position gets no command (the rig's watchdog then acts).
"""
from __future__ import annotations

import math
import sys

from rcl_interfaces.msg import SetParametersResult
from rclpy.clock import Clock, ClockType
from rclpy.duration import Duration
from rclpy.executors import SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
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
from ipfric_ros.parameters import check_unknown, declare, declare_scenario, plain
from ipfric_ros.signals import node_process

#: Parameters that may change while the controller runs.
RUNTIME_PARAMETERS = ('delay', 'gain', 'cutoff_hz', 'voltage_limit')


WRITER_CHECK = 100   # samples between checks that joint_states has a single publisher

class ControllerNode(Node):
    """StateFeedback behind ROS topics and parameters."""

    def __init__(self):
        super().__init__('controller_node')
        read_only = set(Scenario.flat_defaults('controller_node')) - set(RUNTIME_PARAMETERS)
        self.scenario = declare_scenario(self, 'controller_node', read_only=read_only)
        self.min_subscribers = declare(
            self, 'controller_node', 'min_command_subscribers', 1,
            'publish controller_gain (ready) once voltage_command has this many subscriptions', (1, 100),
            read_only=True)
        self.executor_kind = declare(
            self, 'controller_node', 'executor', 'single_threaded',
            'rclpy executor: ' + ' | '.join(EXECUTORS), read_only=True)
        if self.executor_kind not in EXECUTORS:
            raise ConfigError(f'controller_node.ros__parameters.executor: {self.executor_kind!r}; '
                              f'allowed {", ".join(EXECUTORS)}')
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

        self.add_on_set_parameters_callback(self._validate)
        self.add_post_set_parameters_callback(self._apply)
        self.pub_command = self.create_publisher(VoltageCommand, topics.VOLTAGE_COMMAND, topics.data_qos())
        self.pub_gain = self.create_publisher(Float64MultiArray, topics.CONTROLLER_GAIN, topics.latched_qos())
        self.sub_joints = self.create_subscription(JointState, topics.JOINT_STATES, self._on_joints,
                                                   topics.data_qos())
        self.ready = False
        self.published = 0
        self.rejected = 0
        self._seen = 0       # measurements received
        self._writers = 1    # publishers on joint_states at the last check
        self.last_index = None
        self._names = None
        self._index = (0, 1)
        # wall-clock (steady) timer: with use_sim_time the ROS clock stands still until /clock
        self._ready_timer = self.create_timer(0.02, self._check_ready,
                                              clock=Clock(clock_type=ClockType.STEADY_TIME))

    # -- readiness -------------------------------------------------------------------------
    def _check_ready(self) -> None:
        n = self.pub_command.get_subscription_count()
        if n < self.min_subscribers:
            return
        self._ready_timer.cancel()
        self.ready = True
        self._publish_gain()
        self.get_logger().info(f'ready: {topics.VOLTAGE_COMMAND} matched by {n} subscription(s)')

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
            self.get_logger().info(f'{p.name} set to {value}')

    # -- control ---------------------------------------------------------------------------
    def _on_joints(self, msg: JointState) -> None:
        if not self.ready:
            return
        self._seen += 1
        if self._seen % WRITER_CHECK == 1:   # a graph query every WRITER_CHECK samples
            self._writers = self.count_publishers(self.sub_joints.topic_name)
        if self._writers > 1:
            self.rejected += 1
            self.get_logger().error(f'{self._writers} publishers on {self.sub_joints.topic_name}: measurements '
                                    f'refused (only the simulator may write them); no command',
                                    throttle_duration_sec=1.0)
            return
        names = tuple(msg.name)
        if names != self._names:
            try:
                self._index = tuple(names.index(j) for j in topics.JOINT_NAMES)
            except ValueError:
                self.rejected += 1
                self.get_logger().error(f'joint_states without joints {topics.JOINT_NAMES}: {names}',
                                        throttle_duration_sec=1.0)
                return
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
            return
        v = self.controller.update(x, theta)
        cmd = VoltageCommand(voltage=v, measurement_stamp=msg.header.stamp, sample_index=k)
        now = self.get_clock().now()
        cmd.header.stamp = now.to_msg() if now.nanoseconds >= stamp_ns else msg.header.stamp
        self.pub_command.publish(cmd)
        self.published += 1
        self.last_index = k

    def flush(self, timeout: float = 2.0) -> None:
        if not self.pub_command.wait_for_all_acked(Duration(seconds=timeout)):
            self.get_logger().warning(f'{topics.VOLTAGE_COMMAND}: not all commands acknowledged in {timeout:g} s')


#: The executors controller_node can spin with (parameter ``executor``).
EXECUTORS = {'single_threaded': SingleThreadedExecutor, 'events': EventsExecutor}


def main(args=None) -> int:
    with node_process('controller_node', args) as proc:
        try:
            node = proc.add(ControllerNode())
        except ConfigError as exc:
            proc.logger.fatal(f'configuration error: {exc}')
            return 2
        executor = EXECUTORS[node.executor_kind]()
        executor.add_node(node)
        while not proc.stop:
            executor.spin_once(timeout_sec=0.1)
        node.flush()
        proc.logger.info(f'stopped by {proc.stop.reason}: published {node.published} commands (last sample '
                         f'{node.last_index}), rejected {node.rejected} measurements')
        return 0


if __name__ == '__main__':
    sys.exit(main())
