"""recorder: every topic of an ipfric run into a rosbag2 directory with MCAP storage.

Subscribes ``/clock``, ``joint_states``, ``plant_state``, ``voltage_command``,
``safety_event`` and ``controller_gain`` as raw (serialized CDR) messages and writes them
unchanged, under their resolved names (``/joint_states``; ``/ns/joint_states`` when the
recorder runs in namespace ``/ns``), into a rosbag2 directory
(:class:`ipfric_record.bagwriter.BagWriter`):
``<output>/metadata.yaml`` and ``<output>/<name>_0.mcap`` with a schema for every channel,
message indexes and a Statistics record, as rosbag2 itself writes them. Each message is
stamped with the recorder's wall clock when it is taken (as ``ros2 bag record`` does),
never decreasing; the header stamps carry the simulated time.

The run configuration (``scenario_file`` loaded by :func:`ipfric_core.run.scenario.load_scenario`:
plant, friction, plant_truth, sim, controller and the gain) goes into the bag metadata
as JSON under ``ipfric.config`` and as the parameter file text under ``ipfric.scenario_file``:
in an MCAP metadata record ``ipfric`` and in ``custom_data`` of metadata.yaml (and of the
MCAP ``rosbag2`` record).

The recorder waits on its subscriptions alone and takes every queued message at each
wake-up. On SIGINT/SIGTERM it takes every message still queued, closes the bag (so
it stays readable) and exits 0. Subscriptions are reliable with a deep history, so that a
burst the recorder cannot write at once waits in the queue instead of being lost.
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

from ament_index_python.packages import get_package_share_directory
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from ipfric_core.physics.params import ConfigError
from ipfric_core.run.scenario import load_scenario
from ipfric_ros import topics
from ipfric_ros.parameters import check_unknown, declare
from ipfric_ros.rclpy_internals import SubscriptionWaiter
from ipfric_ros.signals import node_process

from .bagwriter import BagWriter, qos_dict


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
    """Raw subscriptions to the run's topics, written to a rosbag2 MCAP directory."""

    def __init__(self):
        super().__init__('recorder')
        output = declare(self, 'recorder', 'output', '',
                         'rosbag2 directory to create; must not exist ("" = ipfric_<date>_<time>)',
                         read_only=True)
        scenario_file = declare(self, 'recorder', 'scenario_file', '',
                                'scenario parameter file of the run, stored in the bag metadata',
                                read_only=True)
        check_unknown(self, 'recorder')
        self.path = Path(output or time.strftime('ipfric_%Y%m%d_%H%M%S'))
        custom = {}
        if scenario_file:
            text = Path(scenario_file).read_text()
            custom['ipfric.config'] = json.dumps(load_scenario(scenario_file).to_dict())
            custom['ipfric.scenario_file'] = text
        store = make_typestore()
        self.writer = BagWriter(self.path, store, custom_data=custom,
                                metadata={'ipfric': custom} if custom else None)
        self.subs = []
        self._last_ns = 0
        for name, (cls, type_name, latched) in topics.run_topics().items():
            depth = 1 if latched else (100 if name == topics.SAFETY_EVENT else topics.DATA_DEPTH)
            resolved = self.resolve_topic_name(name)
            self.writer.add_topic(resolved, type_name, qos_dict(depth=depth, transient_local=latched))
            qos = topics.latched_qos() if latched else topics.data_qos(topics.RECORD_DEPTH)
            sub = self.create_subscription(cls, name, self._writer_for(resolved), qos, raw=True)
            self.subs.append((sub, resolved))
        self.waiter = SubscriptionWaiter(self, *(s for s, _ in self.subs))
        self.get_logger().info(f'recording {len(self.subs)} topics to {self.path}')

    def _log_time(self) -> int:
        """The bag time of a message taken now [ns]: the recorder's clock, never decreasing.

        (The middleware's reception stamps were seen to step back by ~80 ms early in a run.)
        """
        self._last_ns = max(time.time_ns(), self._last_ns)
        return self._last_ns

    def _writer_for(self, name):
        def on_message(data):
            self.writer.write(name, self._log_time(), data)
        return on_message

    def drain(self) -> int:
        """Write every message still queued in the subscriptions; the number taken."""
        taken = 0
        write = self.writer.write
        for i, (_, name) in enumerate(self.subs):
            while (got := self.waiter.take(i)) is not None:
                write(name, self._log_time(), got[0])
                taken += 1
        return taken

    def spin_until(self, stop, batch: float = 0.002) -> None:
        """Record until ``stop``: wait on the subscriptions alone, then take everything queued.

        Waking once per batch of messages instead of once per message (as an executor
        does) keeps the recorder's CPU load low at 4 messages per sample; after each wake-up
        it sleeps ``batch`` s so that messages accumulate. Parameter services are served by
        an executor turn every half second.
        """
        executor = SingleThreadedExecutor()
        executor.add_node(self)
        next_turn = time.monotonic()
        while not stop:
            self.waiter.wait(0.1)
            if self.drain():
                time.sleep(batch)
            if time.monotonic() >= next_turn:
                executor.spin_once(timeout_sec=0.0)
                next_turn = time.monotonic() + 0.5

    def close(self) -> None:
        self.writer.close()
        counts = self.writer.counts()
        self.get_logger().info(f'bag {self.path} closed: {sum(counts.values())} messages {json.dumps(counts)}')


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
        node.close()
        return 0


if __name__ == '__main__':
    sys.exit(main())
