"""The raw rclpy round trip an ipfric lockstep step is compared with.

Two processes on the run's topics, message types and QoS: ``echo`` answers every
``joint_states`` (sensor_msgs/JointState) with a ``voltage_command``
(ipfric_msgs/VoltageCommand), spinning a SingleThreadedExecutor like the controller node;
``ping`` publishes a sample, waits for its answer on a wait set like the simulator's
lockstep loop, and repeats. Nothing else is computed: the rate ``ping`` prints (JSON) is
the most a lockstep loop of two rclpy processes can do on this machine.

    python bench/ros_echo.py echo
    python bench/ros_echo.py ping N
"""
from __future__ import annotations

import json
import sys
import time

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node
from sensor_msgs.msg import JointState

from ipfric_msgs.msg import VoltageCommand
from ipfric_ros import topics


def echo() -> None:
    node = Node('bench_echo')
    pub = node.create_publisher(VoltageCommand, topics.VOLTAGE_COMMAND, topics.data_qos())

    def answer(msg):
        pub.publish(VoltageCommand(voltage=msg.position[0], measurement_stamp=msg.header.stamp,
                                   sample_index=msg.header.stamp.nanosec))
    node.create_subscription(JointState, topics.JOINT_STATES, answer, topics.data_qos())
    ex = SingleThreadedExecutor()
    ex.add_node(node)
    try:
        while rclpy.ok():
            ex.spin_once(timeout_sec=0.1)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass


def ping(n: int) -> None:
    node = Node('bench_ping')
    pub = node.create_publisher(JointState, topics.JOINT_STATES, topics.data_qos())
    sub = node.create_subscription(VoltageCommand, topics.VOLTAGE_COMMAND, lambda m: None, topics.data_qos())
    assert node.context.handle is not None
    ws = _rclpy.WaitSet(1, 0, 0, 0, 0, 0, node.context.handle)
    t0 = time.monotonic()
    while pub.get_subscription_count() < 1 or sub.get_publisher_count() < 1:
        if time.monotonic() - t0 > 30:
            raise SystemExit('echo not matched within 30 s')
        time.sleep(0.01)
    time.sleep(0.2)

    def once(k):
        msg = JointState(name=['cart', 'pendulum'], position=[0.0, 0.0])
        msg.header.stamp.nanosec = k
        pub.publish(msg)
        while True:
            ws.clear_entities()
            ws.add_subscription(sub.handle)
            ws.wait(int(1e9))
            got = sub.handle.take_message(VoltageCommand, False)
            if got is not None and got[0].sample_index == k:
                return
    for k in range(min(100, n)):  # warm up
        once(k)
    t0 = time.perf_counter()
    for k in range(n):
        once(k)
    wall = time.perf_counter() - t0
    print(json.dumps({'round_trips': n, 'wall_s': wall, 'per_s': n / wall}))


if __name__ == '__main__':
    rclpy.init()
    try:
        echo() if sys.argv[1] == 'echo' else ping(int(sys.argv[2]))
    finally:
        rclpy.try_shutdown()
