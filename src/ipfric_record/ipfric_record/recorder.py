"""recorder: every topic of an ipfric rig into a rosbag2 directory with MCAP storage.

Subscribes the rig's ``clock``, ``joint_states``, ``plant_state``, ``voltage_command``,
``safety_event``, ``controller_gain`` and ``diagnostics`` as raw (serialized CDR) messages
and writes them unchanged, under their resolved names (``/joint_states``; ``/rig1/joint_states``
when the recorder runs in namespace ``/rig1``), into a rosbag2 directory
(:class:`ipfric_record.bagwriter.BagWriter`): ``<output>/metadata.yaml`` and
``<output>/<name>_0.mcap`` with a schema for every channel, message indexes and a Statistics
record, as rosbag2 itself writes them. ``/parameter_events`` is recorded too, the changes of
the rig's own nodes only (those in the recorder's namespace; not their start-up declarations):
a ``ros2 param set`` of the controller's delay or gain during the run is in the bag with its simulated-time stamp. Each
message is stamped with the recorder's wall clock when it is taken (as ``ros2 bag record``
does), never decreasing; the header stamps carry the simulated time.

The run configuration (``scenario_file`` loaded by :func:`ipfric_core.run.scenario.load_scenario`:
plant, friction, plant_truth, sim, controller and the gain, as the run started) goes into the
bag metadata as JSON under ``ipfric.config`` and as the parameter file text under
``ipfric.scenario_file``, and how the recording ended under ``ipfric.recording`` (whether the
run's terminal event is in the bag, what stopped the recorder): in an MCAP metadata record
``ipfric`` and in ``custom_data`` of metadata.yaml (and of the MCAP ``rosbag2`` record).

The recorder waits on its subscriptions alone and takes every queued message at each
wake-up. On SIGINT/SIGTERM (a Ctrl-C of ``ros2 launch`` or of a terminal reaches every node
at once) it records on until the simulator's terminal event (END, ABORT, FALLEN,
TRACK_LIMIT) is in the bag, the simulator is gone or ``END_WAIT_S`` passed (a second signal
cuts that short), takes every message still queued and closes the bag (so it stays
readable), exit code 0. Subscriptions are reliable with a deep history, so that a burst the
recorder cannot write at once waits in the queue instead of being lost.
"""
from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

from ament_index_python.packages import get_package_share_directory
from rcl_interfaces.msg import ParameterEvent
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.serialization import deserialize_message, serialize_message
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from ipfric_core.physics.params import ConfigError
from ipfric_core.run.scenario import load_scenario, scenario_path
from ipfric_msgs.msg import SafetyEvent
from ipfric_ros import topics
from ipfric_ros.parameters import check_unknown, declare
from ipfric_ros.rclpy_internals import SubscriptionWaiter
from ipfric_ros.signals import StopRequest, node_process

from .bagwriter import BagWriter, qos_dict

__all__ = ['END_WAIT_S', 'Recorder', 'make_typestore', 'main']

#: [s] after a stop request, the longest wait for the run's terminal event
END_WAIT_S = 4.0
#: executor callbacks (parameter events, service requests) taken at each of its turns
TURNS = 20
PARAMETER_EVENT_TYPE = 'rcl_interfaces/msg/ParameterEvent'


def make_typestore():
    """Kilted's standard message types plus ipfric_msgs (from its installed .msg files)."""
    store = get_typestore(Stores.ROS2_KILTED)
    share = Path(get_package_share_directory('ipfric_msgs')) / 'msg'
    types = {}
    for f in sorted(share.glob('*.msg')):
        types.update(get_types_from_msg(f.read_text(), f'ipfric_msgs/msg/{f.stem}'))
    store.register(types)
    return store


class Recorder(Node):
    """Raw subscriptions to the rig's topics, written to a rosbag2 MCAP directory."""

    def __init__(self):
        super().__init__('recorder', cli_args=topics.RIG_ARGUMENTS)
        output = declare(self, 'recorder', 'output', '',
                         'rosbag2 directory to create; must not exist ("" = ipfric_<date>_<time>)',
                         read_only=True)
        scenario_file = declare(self, 'recorder', 'scenario_file', '',
                                'scenario parameter file of the run (a path or an installed scenario\'s name), stored '
                                'in the bag metadata',
                                read_only=True)
        self.nice = declare(self, 'recorder', 'nice', 0,
                            'niceness of the recorder while it records (a realtime loop at real-time priority goes '
                            'first anyway; 10 gives way to it without the privilege)', (0, 19), read_only=True)
        check_unknown(self, 'recorder')
        self.path = Path(output or time.strftime('ipfric_%Y%m%d_%H%M%S'))
        self.custom = {}
        if scenario_file:
            path = scenario_path(scenario_file)
            text = path.read_text()
            self.custom['ipfric.config'] = json.dumps(load_scenario(path, self.get_namespace()).to_dict())
            self.custom['ipfric.scenario_file'] = text
        store = make_typestore()
        self.writer = BagWriter(self.path, store, custom_data=self.custom,
                                metadata={'ipfric': self.custom} if self.custom else None)
        self.subs = []
        self._last_ns = 0
        self.end_event: str | None = None    # the code of the run's terminal event, once recorded
        for name, (cls, type_name, latched) in topics.run_topics().items():
            depth = 1 if latched else (100 if name == topics.SAFETY_EVENT else topics.DATA_DEPTH)
            resolved = self.resolve_topic_name(name)
            self.writer.add_topic(resolved, type_name, qos_dict(depth=depth, transient_local=latched))
            qos = topics.latched_qos() if latched else topics.data_qos()
            sub = self.create_subscription(cls, name, lambda _: None, qos, raw=True, callback_group=topics.OwnLoop())
            self.subs.append((sub, resolved))
        self.sub_events = next(s for s, name in self.subs if name.endswith('/' + topics.SAFETY_EVENT))
        self.writer.add_topic(topics.PARAMETER_EVENTS, PARAMETER_EVENT_TYPE, qos_dict(depth=1000))
        self.create_subscription(ParameterEvent, topics.PARAMETER_EVENTS, self._on_parameter_event,
                                 topics.data_qos(1000))
        self.waiter = SubscriptionWaiter(self, *(s for s, _ in self.subs))
        self.get_logger().info(f'recording {len(self.subs) + 1} topics to {self.path}')

    def _log_time(self) -> int:
        """The bag time of a message taken now [ns]: the recorder's clock, never decreasing.

        (The middleware's reception stamps were seen to step back by ~80 ms early in a run.)
        """
        self._last_ns = max(time.time_ns(), self._last_ns)
        return self._last_ns

    def write(self, name: str, data) -> None:
        """One serialized message of topic ``name`` into the bag (a terminal event noted)."""
        self.writer.write(name, self._log_time(), data)
        if name == self.sub_events.topic_name and self.end_event is None:
            code = deserialize_message(bytes(data), SafetyEvent).code
            if code in topics.TERMINAL_EVENTS:
                self.end_event = code

    def _on_parameter_event(self, msg: ParameterEvent) -> None:
        """A parameter event of a node of this rig (its namespace) that changes or deletes a parameter into
        the bag; not the declarations at a node's start, which reach the recorder or not depending on which
        process is up first (the bag would differ from run to run)."""
        namespace = msg.node.rsplit('/', 1)[0] or '/'
        if namespace == self.get_namespace() and (msg.changed_parameters or msg.deleted_parameters):
            self.writer.write(topics.PARAMETER_EVENTS, self._log_time(), serialize_message(msg))

    def drain(self) -> int:
        """Write every message still queued in the subscriptions; the number taken."""
        taken = 0
        for i, (_, name) in enumerate(self.subs):
            while (got := self.waiter.take(i)) is not None:
                self.write(name, got[0])
                taken += 1
        return taken

    def spin_until(self, stop: StopRequest, batch: float = 0.002) -> None:
        """Record until ``stop``, then until the run's end is in the bag (see the module's doc).

        Waits on the subscriptions alone, then takes everything queued: waking once per batch
        of messages instead of once per message (as an executor does) keeps the recorder's
        CPU load low at 4 messages per sample; after each wake-up it sleeps ``batch`` s so
        that messages accumulate. Parameter services and parameter events are served by
        executor turns every half second.
        """
        executor = SingleThreadedExecutor()
        executor.add_node(self)
        next_turn = time.monotonic()
        if self.nice:
            os.nice(self.nice)
        stopped_at = None
        while True:
            if stop and stopped_at is None:
                stopped_at = time.monotonic()
                if self.end_event is None and self.sub_events.get_publisher_count():
                    self.get_logger().info(f'stopped by {stop.reason}: recording until the run ends '
                                           f'(at most {END_WAIT_S:g} s; a second signal closes the bag now)')
            if stopped_at is not None and (self.end_event is not None or stop.count > 1
                                           or not self.sub_events.get_publisher_count()
                                           or time.monotonic() - stopped_at > END_WAIT_S):
                for _ in range(TURNS):                   # the last parameter events
                    executor.spin_once(timeout_sec=0.0)
                break
            self.waiter.wait(0.1 if stopped_at is None else 0.02)
            if self.drain():
                time.sleep(batch)
            if time.monotonic() >= next_turn or stopped_at is not None:
                for _ in range(TURNS):
                    executor.spin_once(timeout_sec=0.0)
                next_turn = time.monotonic() + 0.5

    def close(self, stopped_by: str | None) -> None:
        recording = {'complete': self.end_event is not None, 'end_event': self.end_event,
                     'stopped_by': stopped_by, 'namespace': self.get_namespace()}
        self.custom['ipfric.recording'] = json.dumps(recording)
        self.writer.custom_data.update(self.custom)
        self.writer.metadata['ipfric'] = dict(self.custom)
        self.writer.close()
        counts = self.writer.counts()
        self.get_logger().info(f'bag {self.path} closed: {sum(counts.values())} messages {json.dumps(counts)}'
                               + ('' if recording['complete'] else
                                  '; INCOMPLETE: the run\'s end (its terminal event) is not in the bag'))


def main(args=None) -> int:
    with node_process('recorder', args) as proc:
        try:
            node = proc.add(Recorder())
        except (ConfigError, OSError) as exc:
            proc.logger.fatal(f'cannot record: {exc}')
            return 2
        node.spin_until(proc.stop)
        taken = node.drain()
        proc.logger.info(f'stopped by {proc.stop.reason}; {taken} queued messages written at the end')
        node.close(proc.stop.reason)
        return 0


if __name__ == '__main__':
    sys.exit(main())
