"""Topics of an ipfric run: names, message types and QoS, in one place.

Every topic of a rig is relative to the rig's namespace, its clock included: sim_node
publishes ``clock`` (``/rig1/clock``; ``/clock`` at the root) and every ipfric node is
created with :data:`RIG_ARGUMENTS`, which remaps the ``/clock`` a node's time source
follows (``use_sim_time``) to the ``clock`` of its namespace. So several rigs, each in its
namespace, share a ROS domain without sharing a clock.

Data topics are reliable with a history of 10000 samples, writers and readers alike, so
that a recorder that falls behind for seconds (a loaded machine) loses nothing: with 1000
a lockstep run at a load of 9 lost some joint states (1 run in 35); the gain is latched (transient local) so that a late
subscriber still receives it. The clock is published reliable: the best-effort
subscription of a node's time source is compatible with it.
"""
from __future__ import annotations

from rclpy.callback_groups import CallbackGroup
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

# the names are defined once in ipfric_core.constants (the offline analysis reads them too)
from ipfric_core.constants import (
    CLOCK,
    CONTROLLER_GAIN,
    DIAGNOSTICS,
    JOINT_NAMES,
    JOINT_STATES,
    PARAMETER_EVENTS,
    PLANT_STATE,
    SAFETY_EVENT,
    TERMINAL_EVENTS,
    VOLTAGE_COMMAND,
)

__all__ = ['CLOCK', 'CONTROLLER_GAIN', 'DATA_DEPTH', 'DIAGNOSTICS', 'JOINT_NAMES', 'JOINT_STATES', 'PARAMETER_EVENTS',
           'PLANT_STATE', 'RIG_ARGUMENTS', 'SAFETY_EVENT', 'TERMINAL_EVENTS', 'VOLTAGE_COMMAND',
           'OwnLoop', 'data_qos', 'latched_qos', 'run_topics', 'stamp_of_sample', 'stamp_to_ns']

DATA_DEPTH = 10000
#: Node arguments of every ipfric node (``Node(..., cli_args=RIG_ARGUMENTS)``): the time source
#: follows the rig's ``clock``, in the node's namespace.
RIG_ARGUMENTS = ['--ros-args', '-r', '/clock:=clock']


class OwnLoop(CallbackGroup):
    """The group of a subscription that the node's own loop waits on and takes from
    (:class:`ipfric_ros.rclpy_internals.SubscriptionWaiter`); an executor never does."""

    def can_execute(self, entity) -> bool:
        return False

    def beginning_execution(self, entity) -> bool:
        return False

    def ending_execution(self, entity) -> None:
        pass


def data_qos(depth: int = DATA_DEPTH) -> QoSProfile:
    """Reliable, volatile, keep last ``depth``: the sample-rate topics."""
    return QoSProfile(depth=depth, reliability=ReliabilityPolicy.RELIABLE,
                      history=HistoryPolicy.KEEP_LAST, durability=DurabilityPolicy.VOLATILE)


def latched_qos(depth: int = 1) -> QoSProfile:
    """Reliable, transient local: the last value reaches late subscribers."""
    return QoSProfile(depth=depth, reliability=ReliabilityPolicy.RELIABLE,
                      history=HistoryPolicy.KEEP_LAST, durability=DurabilityPolicy.TRANSIENT_LOCAL)


def run_topics() -> dict:
    """Every topic of a rig (relative to its namespace): name -> (message class, ROS type name, latched)."""
    from diagnostic_msgs.msg import DiagnosticArray
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
        DIAGNOSTICS: (DiagnosticArray, 'diagnostic_msgs/msg/DiagnosticArray', False),
    }


def stamp_of_sample(k: int, period_ns: int):
    """builtin_interfaces/Time of sample ``k`` (t_k = k * period, exact in integer ns)."""
    from builtin_interfaces.msg import Time
    ns = k * period_ns
    return Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def stamp_to_ns(stamp) -> int:
    return stamp.sec * 1_000_000_000 + stamp.nanosec
