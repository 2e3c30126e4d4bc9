"""Topics of an ipfric run: names, message types and QoS, in one place.

Data topics are reliable with deep history so that a recorder that falls behind for a
moment loses nothing at 1 kHz; the gain is latched (transient local) so that a late
subscriber still receives it. ``/clock`` is published reliable: the best-effort
subscription of a node's time source is compatible with it.
"""
from __future__ import annotations

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

# the names are defined once in ipfric_core.constants (the offline analysis reads them too)
from ipfric_core.constants import (
    CLOCK,
    CONTROLLER_GAIN,
    JOINT_NAMES,
    JOINT_STATES,
    PLANT_STATE,
    SAFETY_EVENT,
    TERMINAL_EVENTS,
    VOLTAGE_COMMAND,
)

__all__ = ['CLOCK', 'CONTROLLER_GAIN', 'DATA_DEPTH', 'JOINT_NAMES', 'JOINT_STATES', 'PLANT_STATE', 'RECORD_DEPTH',
           'SAFETY_EVENT', 'TERMINAL_EVENTS', 'VOLTAGE_COMMAND', 'data_qos', 'latched_qos', 'run_topics',
           'stamp_of_sample', 'stamp_to_ns']

DATA_DEPTH = 1000
RECORD_DEPTH = 10000


def data_qos(depth: int = DATA_DEPTH) -> QoSProfile:
    """Reliable, volatile, keep last ``depth``: the sample-rate topics."""
    return QoSProfile(depth=depth, reliability=ReliabilityPolicy.RELIABLE,
                      history=HistoryPolicy.KEEP_LAST, durability=DurabilityPolicy.VOLATILE)


def latched_qos(depth: int = 1) -> QoSProfile:
    """Reliable, transient local: the last value reaches late subscribers."""
    return QoSProfile(depth=depth, reliability=ReliabilityPolicy.RELIABLE,
                      history=HistoryPolicy.KEEP_LAST, durability=DurabilityPolicy.TRANSIENT_LOCAL)


def run_topics() -> dict:
    """Every topic of a run: name -> (message class, ROS type name, latched)."""
    from rosgraph_msgs.msg import Clock
    from sensor_msgs.msg import JointState
    from std_msgs.msg import Float64MultiArray

    from ipfric_msgs.msg import PlantState, SafetyEvent, VoltageCommand
    return {
        CLOCK: (Clock, 'rosgraph_msgs/msg/Clock', False),
        JOINT_STATES: (JointState, 'sensor_msgs/msg/JointState', False),
        PLANT_STATE: (PlantState, 'ipfric_msgs/msg/PlantState', False),
        VOLTAGE_COMMAND: (VoltageCommand, 'ipfric_msgs/msg/VoltageCommand', False),
        SAFETY_EVENT: (SafetyEvent, 'ipfric_msgs/msg/SafetyEvent', False),
        CONTROLLER_GAIN: (Float64MultiArray, 'std_msgs/msg/Float64MultiArray', True),
    }


def stamp_of_sample(k: int, period_ns: int):
    """builtin_interfaces/Time of sample ``k`` (t_k = k * period, exact in integer ns)."""
    from builtin_interfaces.msg import Time
    ns = k * period_ns
    return Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def stamp_to_ns(stamp) -> int:
    return stamp.sec * 1_000_000_000 + stamp.nanosec
