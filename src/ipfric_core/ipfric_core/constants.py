"""Names and defaults shared across ipfric, defined once: topic names, how a run ends, the
paper rig's encoder resolutions and safety limits.

It imports nothing of ipfric, so every layer (physics, design, run, analysis, ident) and
the ROS packages can use it: the offline analysis reads topics from a bag without
importing ROS, the physics and the ROS simulator report the same end reasons, and
``ipfric_ros.topics`` re-exports the topic names for the nodes.
"""
from __future__ import annotations

import math
import os
from pathlib import Path

__all__ = ['REPO_ROOT', 'CLOCK', 'DIAGNOSTICS', 'PARAMETER_EVENTS', 'JOINT_STATES', 'PLANT_STATE', 'VOLTAGE_COMMAND',
           'SAFETY_EVENT', 'CONTROLLER_GAIN', 'JOINT_NAMES', 'DURATION', 'FALLEN', 'TRACK_LIMIT', 'START', 'END',
           'ABORT', 'LIMITS', 'TERMINAL_EVENTS', 'EVENT_CODES', 'ANGLE_RESOLUTION_RAD', 'CART_RESOLUTION_M',
           'TRACK_LIMIT_M', 'FALLEN_ANGLE_RAD']

#: the checkout (or the workspace's symlinked source tree) ipfric runs from: its config/, runs/, ros2_ws/;
#: IPFRIC_ROOT overrides it
REPO_ROOT = Path(os.environ.get('IPFRIC_ROOT') or Path(__file__).resolve().parents[3])

# -- topics of a run, relative to the rig's namespace (``/rig1/joint_states``; at the root the usual
# ``/joint_states``, ``/clock``): each rig has its own clock, which every node of the rig follows
CLOCK = 'clock'
DIAGNOSTICS = 'diagnostics'
PARAMETER_EVENTS = '/parameter_events'
JOINT_STATES = 'joint_states'
PLANT_STATE = 'plant_state'
VOLTAGE_COMMAND = 'voltage_command'
SAFETY_EVENT = 'safety_event'
CONTROLLER_GAIN = 'controller_gain'
#: JointState names of the two encoders, in this order.
JOINT_NAMES = ('cart', 'pendulum')

# -- how a run ends
DURATION = 'duration'        # offline closed loop: the whole duration was simulated
FALLEN = 'FALLEN'            # |theta| beyond the fallen angle, or the state is not finite
TRACK_LIMIT = 'TRACK_LIMIT'  # |x| beyond the track limit
START = 'START'              # ROS run: SafetyEvent at sample 0
END = 'END'                  # ROS run: the duration was reached
ABORT = 'ABORT'              # ROS run: stopped from outside or by an error
#: the rig's safety limits, the ends a run can meet by itself (offline and through ROS)
LIMITS = (FALLEN, TRACK_LIMIT)
#: SafetyEvent codes that end a ROS run
TERMINAL_EVENTS = (END, TRACK_LIMIT, FALLEN, ABORT)
#: every SafetyEvent code sim_node publishes (ipfric_msgs/msg/SafetyEvent.msg has a constant for each)
EVENT_CODES = (START, *TERMINAL_EVENTS, 'BAD_COMMAND', 'WATCHDOG', 'STALL', 'INTRUDER')

# -- the paper's rig (section 6) and its safety limits
ANGLE_RESOLUTION_RAD = math.radians(0.08789)   # angle encoder count, 4096 counts/rev [rad]
CART_RESOLUTION_M = 0.00454e-2                 # cart encoder count [m]
TRACK_LIMIT_M = 0.4                            # |x| beyond which a run ends [m]
FALLEN_ANGLE_RAD = math.radians(30.0)          # |theta| beyond which the pendulum has fallen [rad]
