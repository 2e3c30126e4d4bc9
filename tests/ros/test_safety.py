"""Command safety of the simulator and input checks of the controller.

Unit level: the simulator's command validation and watchdog (ipfric_sim.safety).
Live: each node against a peer in the test process (its own ROS domain on loopback):
the simulator receiving NaN, infinite and out-of-range commands; the controller
receiving a NaN measurement and refusing bad parameter values at run time.
"""
import json
import math

import pytest
from rosrun import Peer, scenario_file, start_node

from ipfric_ros import topics
from ipfric_sim.safety import BAD_COMMAND, WATCHDOG, CommandGuard, check_command


@pytest.mark.parametrize('v, reason', [
    (math.nan, 'voltage is NaN'), (math.inf, 'voltage is +inf'), (-math.inf, 'voltage is -inf'),
    (10.5, '|V| = 10.5 V exceeds voltage_max = 10 V'), (-11.0, '|V| = 11 V exceeds voltage_max = 10 V'),
    ('3', "voltage '3' is not a number"), (None, 'voltage None is not a number'),
])
def test_check_command_refuses(v, reason):
    assert check_command(v, 10.0) == reason


@pytest.mark.parametrize('v', [0.0, 10.0, -10.0, 3.25])
def test_check_command_accepts(v):
    assert check_command(v, 10.0) is None


def test_guard_zero_order_hold_bad_command_and_watchdog():
    g = CommandGuard(voltage_max=10.0, watchdog_samples=3)
    assert g.apply(2.0) == (2.0, [])
    assert g.apply(None) == (2.0, [])                       # held
    v, ev = g.apply(math.nan, k=2, now=0.0)
    assert v == 0.0 and ev == [(BAD_COMMAND, 'command refused at sample 2: voltage is NaN; 0 V applied')]
    v, ev = g.apply(None)                                    # third sample without a valid command
    assert v == 0.0 and [c for c, _ in ev] == [WATCHDOG] and g.tripped
    assert g.apply(50.0, k=4, now=0.1) == (0.0, [])         # counted, reported with its burst
    assert g.apply(math.inf, k=5, now=0.2) == (0.0, [])
    assert g.refusals.report(0.5) is None                    # one report per second at most
    assert g.refusals.report(1.0) == '2 more command(s) refused since sample 4: 1 inf, 1 out of range'
    assert g.apply(1.5) == (1.5, []) and not g.tripped       # valid commands resume
    assert g.refused == 3 and g.missing == 2 and g.trips == 1


def test_a_burst_of_refusals_gives_two_events_with_counts():
    g = CommandGuard(voltage_max=10.0, watchdog_samples=10 ** 6)
    events = [ev for k in range(5000) for ev in g.apply(math.nan, k=k, now=k * 2e-4)[1]]
    events += [(BAD_COMMAND, g.refusals.report(1.0, force=True))]
    assert [c for c, _ in events] == [BAD_COMMAND, BAD_COMMAND]
    assert events[1][1] == '4999 more command(s) refused since sample 1: 4999 NaN'
    assert g.refused == 5000


def fake_controller(peer):
    """The peer as the simulator's controller: its gain announced (latched); its command publisher."""
    from std_msgs.msg import Float64MultiArray

    from ipfric_msgs.msg import VoltageCommand
    gain_pub = peer.node.create_publisher(Float64MultiArray, topics.CONTROLLER_GAIN, topics.latched_qos())
    gain_pub.publish(Float64MultiArray(data=[0.0, 0.0, 0.0, 0.0]))
    return peer.node.create_publisher(VoltageCommand, topics.VOLTAGE_COMMAND, topics.data_qos())


def test_sim_refuses_nan_inf_and_out_of_range_commands(tmp_path):
    from sensor_msgs.msg import JointState

    from ipfric_msgs.msg import PlantState, SafetyEvent, VoltageCommand
    bad = {10: math.nan, 20: math.inf, 30: 25.0}
    cfg = scenario_file(tmp_path, 'fig7_old_gain_exponential.yaml', sim={'duration': 0.05})
    peer = Peer('fake_controller')
    sim = None
    try:
        node = peer.node
        cmd_pub = fake_controller(peer)
        events, applied = [], {}

        def on_joints(msg):
            k = round(topics.stamp_to_ns(msg.header.stamp) / 1e6)
            cmd = VoltageCommand(voltage=bad.get(k, 1.0), measurement_stamp=msg.header.stamp, sample_index=k)
            cmd_pub.publish(cmd)
        node.create_subscription(JointState, topics.JOINT_STATES, on_joints, topics.data_qos())
        node.create_subscription(SafetyEvent, topics.SAFETY_EVENT, events.append, topics.data_qos(100))
        node.create_subscription(PlantState, topics.PLANT_STATE,
                                 lambda m: applied.__setitem__(m.sample_index, m.voltage_applied),
                                 topics.data_qos())
        sim = start_node('sim_node', ['--params-file', str(cfg), '-p', 'start_timeout_s:=20.0',
                                      '-p', f'result_file:={tmp_path / "result.json"}',
                                      '-p', 'wait_for_recorder:=false', '-p', 'controller_node:=/fake_controller'],
                         peer.domain, tmp_path / 'sim.log')
        peer.spin_until(lambda: any(e.code == 'END' for e in events), 60, 'the END event')
        assert sim.wait(timeout=30) == 0
        peer.spin_until(lambda: len(applied) == 51, 10, 'every plant_state')
    finally:
        peer.close()
        if sim is not None and sim.poll() is None:
            sim.kill()
            sim.wait()
    codes = [(e.sample_index, e.code) for e in events]
    assert codes == [(0, 'START'), (10, BAD_COMMAND), (50, BAD_COMMAND), (50, 'END')]   # one burst
    details = [e.detail for e in events if e.code == BAD_COMMAND]
    assert 'sample 10: voltage is NaN' in details[0]
    assert details[1] == '2 more command(s) refused since sample 20: 1 inf, 1 out of range'
    result = json.loads((tmp_path / 'result.json').read_text())
    assert result['commands_refused'] == 3 and result['refused_by_kind'] == {'NaN': 1, 'inf': 1, 'out of range': 1}
    # V_k acts over [t_k, t_k+1): plant_state k+1 shows it
    for k in range(1, 51):
        assert applied[k] == (0.0 if k - 1 in bad else 1.0), k
    log = (tmp_path / 'sim.log').read_text()
    assert 'BAD_COMMAND at sample 10' in log and 'voltage is NaN' in log


def test_controller_skips_nan_measurements_and_validates_parameters(tmp_path):
    from builtin_interfaces.msg import Time
    from rcl_interfaces.srv import SetParameters
    from rclpy.parameter import Parameter
    from sensor_msgs.msg import JointState
    from std_msgs.msg import Float64MultiArray

    from ipfric_msgs.msg import VoltageCommand
    cfg = scenario_file(tmp_path, 'fig9_new_gain_exponential.yaml')
    peer = Peer('fake_sim')
    ctl = None
    try:
        node = peer.node
        js_pub = node.create_publisher(JointState, topics.JOINT_STATES, topics.data_qos())
        cmds, gains = {}, []
        node.create_subscription(VoltageCommand, topics.VOLTAGE_COMMAND,
                                 lambda m: cmds.__setitem__(m.sample_index, m), topics.data_qos())
        node.create_subscription(Float64MultiArray, topics.CONTROLLER_GAIN,
                                 lambda m: gains.append(list(m.data)), topics.latched_qos())
        ctl = start_node('controller_node', ['--params-file', str(cfg), '-p', 'use_sim_time:=true',
                                             '-p', 'rig_node:=/fake_sim', '-p', 'min_command_subscribers:=1'],
                         peer.domain, tmp_path / 'controller.log')
        peer.spin_until(lambda: gains and js_pub.get_subscription_count() >= 1, 60, 'the controller')
        assert gains[0] == [70.7107, 304.9273, 143.3152, 61.0833]

        def send(k, theta):
            msg = JointState(name=['cart', 'pendulum'], position=[0.0, theta])
            msg.header.stamp = Time(sec=0, nanosec=k * 1_000_000)
            js_pub.publish(msg)
        for k in range(10):
            send(k, math.nan if k == 5 else 0.01)
        peer.spin_until(lambda: 9 in cmds, 30, 'the command for sample 9')
        assert sorted(cmds) == [0, 1, 2, 3, 4, 6, 7, 8, 9]        # nothing for the NaN sample
        assert cmds[9].measurement_stamp.nanosec == 9_000_000
        assert cmds[0].voltage == pytest.approx(304.9273 * 0.01)  # K . (0, 0.01, 0, 0)

        client = node.create_client(SetParameters, '/controller_node/set_parameters')
        peer.spin_until(client.service_is_ready, 30, 'the parameter service')

        def set_param(name, value):
            req = SetParameters.Request(parameters=[Parameter(name, value=value).to_parameter_msg()])
            fut = client.call_async(req)
            peer.spin_until(fut.done, 30, f'set {name}')
            return fut.result().results[0]
        r = set_param('delay', 0.0015)
        assert not r.successful and 'not a multiple of the sample period' in r.reason
        r = set_param('gain', [1.0, 2.0, 3.0])
        assert not r.successful and 'expected 4 finite numbers' in r.reason
        r = set_param('gain', [1.0, 2.0, math.nan, 4.0])
        assert not r.successful
        r = set_param('sample_rate_hz', 500.0)
        assert not r.successful                                    # read-only
        assert set_param('delay', 0.002).successful
        assert set_param('gain', [1.0, 2.0, 3.0, 4.0]).successful
        peer.spin_until(lambda: gains[-1] == [1.0, 2.0, 3.0, 4.0], 30, 'the new gain on controller_gain')
    finally:
        peer.close()
        if ctl is not None:
            ctl.send_signal(2)
            assert ctl.wait(timeout=30) == 0
    log = (tmp_path / 'controller.log').read_text()
    assert 'sample 5: position not finite' in log
    assert 'delay set to 0.002' in log and 'rejected 1 measurements' in log


def test_controller_designs_the_gain_at_start_up(tmp_path):
    """gain_source: design: LQR on the exponential model at start-up gives gain (23), published latched."""
    from std_msgs.msg import Float64MultiArray
    cfg = scenario_file(tmp_path, 'fig9_new_gain_exponential.yaml', controller={'gain_source': 'design'})
    text = cfg.read_text().replace('gain_source: design', '''gain_source: design
    design_friction: {model: exponential, mu_s: 0.0861, mu_c: 0.04287, eps: 3.0, v_s: 0.105, gamma: 2.0,
                      smoothing: none, delta: 100.0}''')
    cfg.write_text(text)
    peer = Peer('gain_listener')
    ctl = None
    try:
        gains = []
        peer.node.create_subscription(Float64MultiArray, topics.CONTROLLER_GAIN,
                                      lambda m: gains.append(list(m.data)), topics.latched_qos())
        # the controller announces itself once a command subscription exists
        from ipfric_msgs.msg import VoltageCommand
        peer.node.create_subscription(VoltageCommand, topics.VOLTAGE_COMMAND, lambda m: None, topics.data_qos())
        from sensor_msgs.msg import JointState
        peer.node.create_publisher(JointState, topics.JOINT_STATES, topics.data_qos())   # the rig, as the controller
        ctl = start_node('controller_node', ['--params-file', str(cfg), '-p', 'rig_node:=/gain_listener',
                                             '-p', 'min_command_subscribers:=1'], peer.domain, tmp_path / 'ctl.log')
        peer.spin_until(lambda: gains, 60, 'controller_gain')
    finally:
        peer.close()
        if ctl is not None:
            ctl.send_signal(2)
            assert ctl.wait(timeout=30) == 0
    assert gains[0] == pytest.approx([70.7107, 304.9273, 143.3152, 61.0833], rel=1e-4)
    assert 'designed by LQR on the exponential friction model' in (tmp_path / 'ctl.log').read_text()


def test_a_parameter_request_sent_as_the_run_ends_is_answered(tmp_path):
    """`ros2 param set /sim_node ...` sent in the last samples of a run: the simulator answers it (a
    refusal, its parameters are read-only) before its services go, instead of leaving the caller hanging."""
    from rcl_interfaces.srv import SetParameters
    from rclpy.parameter import Parameter
    from sensor_msgs.msg import JointState

    from ipfric_msgs.msg import VoltageCommand
    cfg = scenario_file(tmp_path, 'fig7_old_gain_exponential.yaml', sim={'duration': 0.5})
    peer = Peer('fake_controller')
    sim = None
    try:
        node = peer.node
        cmd_pub = fake_controller(peer)
        client = node.create_client(SetParameters, '/sim_node/set_parameters')
        calls = []

        def on_joints(msg):
            k = round(topics.stamp_to_ns(msg.header.stamp) / 1e6)
            if k == 450:                                 # 50 samples before the end
                req = SetParameters.Request(parameters=[Parameter('theta0', value=0.1).to_parameter_msg()])
                calls.append(client.call_async(req))
            cmd_pub.publish(VoltageCommand(voltage=0.0, measurement_stamp=msg.header.stamp, sample_index=k))
        node.create_subscription(JointState, topics.JOINT_STATES, on_joints, topics.data_qos())
        sim = start_node('sim_node', ['--params-file', str(cfg), '-p', 'wait_for_recorder:=false',
                                      '-p', 'controller_node:=/fake_controller'], peer.domain, tmp_path / 'sim.log')
        peer.spin_until(client.service_is_ready, 60, 'the parameter service')
        peer.spin_until(lambda: calls and calls[0].done(), 30, 'the answer to a request sent as the run ends')
        assert sim.wait(timeout=30) == 0
    finally:
        peer.close()
        if sim is not None and sim.poll() is None:
            sim.kill()
            sim.wait()
    answer = calls[0].result().results[0]
    assert not answer.successful and 'read-only' in answer.reason


@pytest.mark.slow
def test_the_sim_waits_for_the_recorder_on_each_of_its_topics(tmp_path):
    """A recorder must get every message the simulator published: the simulator names the topic whose
    subscription it waits for (the diagnostics, here) and starts once it matches; the last diagnostics,
    published with the last sample, arrive."""
    import time

    from diagnostic_msgs.msg import DiagnosticArray
    from rosgraph_msgs.msg import Clock
    from sensor_msgs.msg import JointState

    from ipfric_msgs.msg import PlantState, SafetyEvent, VoltageCommand
    cfg = scenario_file(tmp_path, 'fig7_old_gain_exponential.yaml', sim={'duration': 1.0, 'theta0': 0.0})
    peer = Peer('fake_controller')
    sim = None
    try:
        node = peer.node
        cmd_pub = fake_controller(peer)
        events, diagnostics = [], []

        def on_joints(msg):
            k = round(topics.stamp_to_ns(msg.header.stamp) / 1e6)
            cmd_pub.publish(VoltageCommand(voltage=0.0, measurement_stamp=msg.header.stamp, sample_index=k))
        node.create_subscription(JointState, topics.JOINT_STATES, on_joints, topics.data_qos())
        node.create_subscription(JointState, topics.JOINT_STATES, lambda m: None, topics.data_qos())
        node.create_subscription(PlantState, topics.PLANT_STATE, lambda m: None, topics.data_qos())
        node.create_subscription(Clock, topics.CLOCK, lambda m: None, topics.data_qos())
        node.create_subscription(SafetyEvent, topics.SAFETY_EVENT, events.append, topics.data_qos(100))
        log = tmp_path / 'sim.log'
        sim = start_node('sim_node', ['--params-file', str(cfg), '-p', 'start_timeout_s:=60.0',
                                      '-p', 'controller_node:=/fake_controller'], peer.domain, log)
        peer.spin_until(lambda: sim.poll() is not None or log.exists() and 'waiting for' in log.read_text(), 60,
                        'the wait to be logged')
        assert sim.poll() is None, log.read_text()[-2000:]
        waiting = [ln for ln in log.read_text().splitlines() if 'waiting for' in ln][-1]
        assert f'/{topics.DIAGNOSTICS}: 0/1 subscribers' in waiting and 'joint_states' not in waiting, waiting
        assert not events and 'START' not in log.read_text()
        node.create_subscription(DiagnosticArray, topics.DIAGNOSTICS, diagnostics.append, topics.data_qos())
        peer.spin_until(lambda: sim.poll() is not None, 60, 'the simulator to end')
        t0 = time.monotonic()
        while time.monotonic() - t0 < 1.0:
            peer.executor.spin_once(timeout_sec=0.05)
    finally:
        peer.close()
        if sim is not None and sim.poll() is None:
            sim.kill()
            sim.wait()
    assert sim.returncode == 0 and events and (events[0].code, events[-1].code) == ('START', 'END'), events
    assert [(d.header.stamp.sec, d.header.stamp.nanosec) for d in diagnostics] == [(1, 0)]   # sample 1000, the last


def test_the_end_waits_for_every_published_topic_to_be_acknowledged():
    """At the end the simulator waits until each of its publishers' messages is acknowledged by every
    subscriber (reliable QoS), the diagnostics included: under load a bag lost the last diagnostics,
    published with the last sample (11 of 12 recorded)."""
    from ipfric_sim.sim_node import SimNode

    class Publisher:
        def __init__(self, name, acked_after):
            self.topic_name, self.left = name, acked_after

        def wait_for_all_acked(self, timeout):
            self.left -= 1
            return self.left <= 0

    class Executor:
        def spin_once(self, timeout_sec):
            pass

    class Node:
        _executor = Executor()
        pub_event, pub_joints, pub_state, pub_clock = (Publisher(f'/{n}', 1) for n in ('e', 'j', 's', 'c'))
        pub_diagnostics = Publisher('/diagnostics', 3)      # acknowledged on the third wait
        recorded_publishers = SimNode.recorded_publishers

        def get_logger(self):
            raise AssertionError('a timeout was logged')
    node = Node()
    SimNode.flush_end(node)
    assert node.pub_diagnostics.left == 0
    assert all(p.left == 0 for p in (node.pub_event, node.pub_joints, node.pub_state, node.pub_clock))
