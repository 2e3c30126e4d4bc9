"""The bare rclpy loops an ipfric run is compared with.

Two processes on the run's topics, message types and QoS: ``echo`` answers every
``joint_states`` (sensor_msgs/JointState) with a ``voltage_command``
(ipfric_msgs/VoltageCommand), spinning a SingleThreadedExecutor as a plain rclpy node does.

- ``ping N``: publishes a sample, waits for its answer on a wait set like the simulator's
  lockstep loop, and repeats: the rate it prints (JSON) is the most a lockstep loop of two
  rclpy processes can do on this machine.
- ``deadline N``: a bare 1 kHz deadline loop, sample k published at t0 + k ms, the answers
  taken until the next deadline; a sample whose previous answer had not arrived by its
  deadline is stale (what the realtime simulator counts as a sample without a fresh command),
  latency from publishing to taking the answer. Nothing else: no physics, no recorder, no
  tuning; the reference of ipfric's realtime loop.

    python bench/ros_echo.py echo
    python bench/ros_echo.py ping N
    python bench/ros_echo.py deadline N
"""
from __future__ import annotations

import json
import sys
import time
from array import array

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
        k = msg.header.stamp.sec * 1000 + msg.header.stamp.nanosec // 1_000_000
        pub.publish(VoltageCommand(voltage=msg.position[0], measurement_stamp=msg.header.stamp, sample_index=k))
    node.create_subscription(JointState, topics.JOINT_STATES, answer, topics.data_qos())
    ex = SingleThreadedExecutor()
    ex.add_node(node)
    try:
        while rclpy.ok():
            ex.spin_once(timeout_sec=0.1)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass


def matched(name: str):
    """(node, publisher, subscription, wait set) of a loop's end matched with the echo."""
    node = Node(name)
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
    return node, pub, sub, ws


def deadline(n: int, period: float = 1e-3) -> None:
    _, pub, sub, ws = matched('bench_deadline')
    sent = array('d', bytes(8 * n))
    latency = array('d')
    answered = bytearray(n)
    stale = 0

    def take(timeout: float) -> None:
        ws.clear_entities()
        ws.add_subscription(sub.handle)
        ws.wait(max(0, int(timeout * 1e9)))
        while (got := sub.handle.take_message(VoltageCommand, False)) is not None:
            k = got[0].sample_index
            if 0 <= k < n and not answered[k]:
                answered[k] = 1
                latency.append(time.monotonic() - sent[k])
    t0 = time.monotonic()
    for k in range(n):
        due = t0 + k * period
        while (now := time.monotonic()) < due:
            take(due - now)
        take(0.0)
        if k and not answered[k - 1]:
            stale += 1
        msg = JointState(name=['cart', 'pendulum'], position=[0.0, 0.0])
        msg.header.stamp.sec, msg.header.stamp.nanosec = k // 1000, (k % 1000) * 1_000_000
        pub.publish(msg)
        sent[k] = time.monotonic()
    lat = sorted(latency)
    print(json.dumps({'samples': n, 'stale': stale, 'answers': len(lat),
                      'latency_s': {'median': lat[len(lat) // 2], 'p99': lat[int(0.99 * (len(lat) - 1))],
                                    'max': lat[-1]} if lat else None}))


def ping(n: int) -> None:
    _, pub, sub, ws = matched('bench_ping')

    def once(k):
        msg = JointState(name=['cart', 'pendulum'], position=[0.0, 0.0])
        msg.header.stamp.sec, msg.header.stamp.nanosec = k // 1000, (k % 1000) * 1_000_000
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
        {'echo': lambda: echo(), 'ping': lambda: ping(int(sys.argv[2])),
         'deadline': lambda: deadline(int(sys.argv[2]))}[sys.argv[1]]()
    finally:
        rclpy.try_shutdown()
