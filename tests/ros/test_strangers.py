"""A rig keeps its own loop whatever a stranger publishes on its topics.

A second process (another node in the run's domain and namespace) publishes on the rig's
topics from before the nodes start to the run's end: idle, a flood of bad commands, commands for the
very samples the controller answers, bogus joint states. The controller obeys the simulator's
measurements only and the simulator its controller's commands only (by publisher), so the
pendulum stays balanced: the lockstep trajectory is the offline closed loop's, bit for bit,
with the stranger counted and reported (INTRUDER, exit code 3).
"""
import json
import math
import time

import numpy as np
import pytest
from rosrun import run_beside_peer, scenario_file

from ipfric_core.analysis.bagread import read_run
from ipfric_core.physics.closedloop import run_closed_loop
from ipfric_core.run.runner import EXIT_FAULT
from ipfric_core.run.scenario import load_scenario

pytestmark = pytest.mark.ros
DURATION = 8.0



def idle(peer, topics):
    from sensor_msgs.msg import JointState
    peer.node.create_publisher(JointState, topics.JOINT_STATES, topics.data_qos())
    return lambda: time.sleep(0.01)


def command_flood(peer, topics):
    from rclpy._rclpy_pybind11 import RCLError

    from ipfric_msgs.msg import VoltageCommand
    pub = peer.node.create_publisher(VoltageCommand, topics.VOLTAGE_COMMAND, topics.data_qos())
    sent = [0]

    def tick():                                     # NaN, inf, 1e6 V for a sample far ahead, ~5 kHz
        for v in (math.nan, math.inf, -1e6):
            try:
                pub.publish(VoltageCommand(voltage=v, sample_index=10 ** 6 + sent[0]))
                sent[0] += 1
            except RCLError:                        # the writer's queue full: the flood goes on
                pass
        time.sleep(5e-4)
    return tick


def matching_commands(peer, topics):
    """+10 V for exactly the sample the simulator waits for (the index of each measurement seen)."""
    from sensor_msgs.msg import JointState

    from ipfric_msgs.msg import VoltageCommand
    pub = peer.node.create_publisher(VoltageCommand, topics.VOLTAGE_COMMAND, topics.data_qos())

    def answer(msg):
        k = round(topics.stamp_to_ns(msg.header.stamp) / 1e6)
        pub.publish(VoltageCommand(voltage=10.0, measurement_stamp=msg.header.stamp, sample_index=k))
    peer.node.create_subscription(JointState, topics.JOINT_STATES, answer, topics.data_qos())
    return lambda: peer.executor.spin_once(timeout_sec=0.01)


def bogus_joint_states(peer, topics):
    """A 'fallen' angle stamped as each of the rig's samples, published as soon as the sample is seen."""
    from sensor_msgs.msg import JointState
    pub = peer.node.create_publisher(JointState, topics.JOINT_STATES, topics.data_qos())
    sent = set()

    def mirror(msg):                                # our own copies come back with a stamp already sent
        stamp = topics.stamp_to_ns(msg.header.stamp)
        if stamp not in sent:
            sent.add(stamp)
            bogus = JointState(name=list(topics.JOINT_NAMES), position=[0.0, 0.4])
            bogus.header.stamp = msg.header.stamp
            pub.publish(bogus)
    peer.node.create_subscription(JointState, topics.JOINT_STATES, mirror, topics.data_qos())
    return lambda: peer.executor.spin_once(timeout_sec=0.01)


@pytest.mark.parametrize('stranger', [idle, command_flood, matching_commands, bogus_joint_states],
                         ids=lambda f: f.__name__)
def test_a_stranger_leaves_the_rig_balanced_and_is_reported(tmp_path, stranger):
    from ipfric_ros import topics
    cfg = scenario_file(tmp_path, 'default.yaml', sim={'duration': DURATION})
    with run_beside_peer(cfg, tmp_path / 'run', 'rogue', setup=lambda peer: stranger(peer, topics)) as (r, _, tick):
        while r.procs['sim_node'].poll() is None:
            tick()
        res = r.wait()
    assert res.exit_code == EXIT_FAULT and res.end_reason == 'END', res.summary()
    assert any('/rogue' in f for f in res.faults), res.faults
    sim = json.loads((tmp_path / 'run' / 'sim_result.json').read_text())
    assert '/rogue' in sum(sim['intruders'].values(), [])
    counts = ('watchdog_trips', 'stalls', 'samples_without_command')
    assert {k: sim[k] for k in counts} == dict.fromkeys(counts, 0), sim['late_answers']
    # the loop never obeyed the stranger: the ground truth is the offline closed loop's
    bag = read_run(res.bag)
    scn = load_scenario(tmp_path / 'run' / 'scenario.yaml')
    tr = run_closed_loop(scn.make_rig(), scn.make_controller(), scn.sim.duration)
    truth = np.column_stack([bag.truth[k] for k in ('x', 'theta', 'x_dot', 'theta_dot')])
    assert truth.shape == tr.state.shape and np.max(np.abs(truth - tr.state)) < 1e-9
    assert np.abs(bag.truth['theta']).max() < 0.05                  # balanced
    assert any(code == 'INTRUDER' and '/rogue' in detail for _, code, detail in bag.events)
    controller_log = (tmp_path / 'run' / 'logs' / 'controller_node.log').read_text()
    if stranger is bogus_joint_states:
        assert 'joint_states from /rogue, not /sim_node: refused' in controller_log
        assert 'sample(s) whose stamp another message has too' in ' '.join(bag.damage)   # analyze says so
    if stranger in (command_flood, matching_commands):
        assert sim['refused_by_publisher'].get('/rogue', 0) > 100
