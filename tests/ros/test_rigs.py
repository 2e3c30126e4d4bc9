"""Rigs as a lab runs them: two namespaced rigs side by side in one ROS domain, a run-time
delay change on the record, a node stopped from outside."""
import json
import signal
import time

import numpy as np
import pytest
from rosrun import CONFIG, run_beside_peer, scenario_file, started

from ipfric_core.analysis.bagread import read_run
from ipfric_core.analysis.recorded_run import analyze_run
from ipfric_core.physics.closedloop import run_closed_loop
from ipfric_core.physics.params import ConfigError
from ipfric_core.run.runner import Run, pick_domain
from ipfric_core.run.scenario import load_scenario

pytestmark = pytest.mark.ros



def test_two_rigs_in_one_domain_each_record_their_own(tmp_path):
    """/rig1 runs Figure 7, /rig2 Figure 9, in one domain at once: each bag holds its rig's topics only,
    every message its simulator published, the trajectory of its own scenario; a third run in /rig1 or
    one at the root of that domain is refused while they run."""
    domain = pick_domain()
    rigs = {'/rig1': ('fig7_old_gain_exponential', 5.0), '/rig2': ('fig9_new_gain_exponential', 4.0)}
    runs = {ns: Run(CONFIG / f'{name}.yaml', tmp_path / ns.strip('/'), duration, domain=domain, namespace=ns,
                    timeout=300) for ns, (name, duration) in rigs.items()}
    try:
        for r in runs.values():
            r.start()
        for ns in ('/rig1', '/'):
            with pytest.raises(ConfigError, match='in use by another ./ipfric run'):
                Run(CONFIG / 'default.yaml', tmp_path / 'third', 1.0, domain=domain, namespace=ns).prepare()
        results = {ns: r.wait() for ns, r in runs.items()}
    finally:
        for r in runs.values():
            r.kill()
    for ns, res in results.items():
        assert res.exit_code == 0 and res.end_reason == 'END' and res.counts_match, res.summary()
        bag = read_run(res.bag)
        assert bag.namespace == ns and bag.intact and not bag.incomplete
        assert {t for t in bag.counts if t != '/parameter_events'} == {
            f'{ns}/{t}' for t in ('clock', 'joint_states', 'plant_state', 'voltage_command', 'safety_event',
                                  'controller_gain', 'diagnostics')}
        scn = load_scenario(f'{res.out}/scenario.yaml')
        tr = run_closed_loop(scn.make_rig(), scn.make_controller(), scn.sim.duration)
        assert len(bag.t) == len(tr.t) and np.max(np.abs(bag.voltage - tr.voltage)) < 1e-9, ns
        assert bag.gain == scn.gain()
        a = analyze_run(res.out)
        assert a['namespace'] == ns and a['samples'] == len(tr.t) and not a['incomplete']
    assert read_run(results['/rig1'].bag).gain != read_run(results['/rig2'].bag).gain


def test_a_run_time_delay_change_is_in_the_bag_and_in_analyze(tmp_path):
    """ros2 param set of the controller's delay during a run (first `delay 0`, an integer, then 0.02 s):
    /parameter_events in the bag, stamped in simulated time at the sample the controller applied it
    from, and analyze's time line cut there into the regime before and the one after."""
    from rcl_interfaces.srv import SetParameters
    from rclpy.parameter import Parameter
    from sensor_msgs.msg import JointState

    from ipfric_ros import topics
    cfg = scenario_file(tmp_path, 'fig9_new_gain_exponential.yaml', sim={'duration': 20.0})
    seen = [0]

    def setup(peer):
        peer.node.create_subscription(JointState, topics.JOINT_STATES,      # the latest sample, not a backlog
                                      lambda m: seen.__setitem__(0, m.header.stamp.sec), topics.data_qos(1))
        return peer.node.create_client(SetParameters, '/controller_node/set_parameters')
    with run_beside_peer(cfg, tmp_path / 'run', 'lab_user', setup=setup) as (r, peer, client):
        peer.spin_until(client.service_is_ready, 60, 'the parameter service')

        def set_delay(value):
            req = SetParameters.Request(parameters=[Parameter('delay', value=value).to_parameter_msg()])
            fut = client.call_async(req)
            peer.spin_until(fut.done, 30, 'set delay')
            return fut.result().results[0]
        result = set_delay(0)                      # an integer, as `ros2 param set ... delay 0` sends it
        assert result.successful, result.reason
        peer.spin_until(lambda: seen[0] >= 2, 60, 'simulated second 2')
        assert set_delay(0.02).successful
        res = r.wait()
    assert res.exit_code == 0, res.summary()
    log = (tmp_path / 'run' / 'logs' / 'controller_node.log').read_text()
    first = int(log.split('delay set to 0.02 (from sample ')[1].split(' ')[0])
    assert 2000 <= first < 20000
    bag = read_run(res.bag)
    changes = [(t, name, value) for t, node, name, value in bag.parameter_changes if node == '/controller_node']
    assert [(n, v) for _, n, v in changes] == [('delay', 0.0), ('delay', 0.02)]
    assert abs(round(changes[1][0] * 1000) - first) <= 2        # stamped in simulated time, within 2 samples
    a = analyze_run(res.out)
    assert [(c['parameter'], c['before'], c['after']) for c in a['parameter_changes']] == [
        ('delay', 0.0, 0.0), ('delay', 0.0, 0.02)]
    spans = a['parameter_regimes']
    assert len(spans) == 2 and spans[1]['after'] == ['delay 0.02']
    assert abs(spans[0]['end'] - changes[1][0]) < 0.002       # cut at the change (`delay 0` changed nothing)
    # 20 ms of delay: gain (23) hunts, twice as wide as it settled. The stretch after the change is judged
    # on its last min(8 s, half its length): 20 s runs so that the growth into the hunt, a few seconds
    # after a change that lands at 2-5 s (it follows the wall clock), is left out (12 s runs, judged on
    # their last 5 s, were once 'growing' with the change at 2.04 s, and once irregular)
    before, after = spans
    assert after['cls'] in ('limit_cycle', 'irregular'), spans
    assert after['x_p2p'] > 1.5 * before['x_p2p'] and after['theta_p2p'] > 1.5 * before['theta_p2p'], spans


@pytest.mark.parametrize('node', ['sim_node', 'controller_node', 'recorder'])
def test_a_node_stopped_from_outside_fails_the_run_and_says_so(tmp_path, node):
    """SIGTERM to one node mid-run (not by ./ipfric run): exit 1, the node and the signal named; a
    recorder stopped so leaves a bag analyze calls incomplete."""
    r = Run(CONFIG / 'default.yaml', tmp_path / 'run', duration=0.0, timeout=300, grace=3.0)
    r.start()
    try:
        started(r.logs['sim_node'], r.procs['sim_node'])
        time.sleep(1.0)                           # mid-run (not a discovery wait)
        r.procs[node].send_signal(signal.SIGTERM)
        res = r.wait()
    finally:
        r.kill()
    assert res.exit_code == 1, res.summary()
    assert any(node in f and 'SIGTERM' in f for f in res.failures), res.failures
    a = analyze_run(res.out)
    if node == 'recorder':
        assert 'the recording stopped before the run ended (the recorder was stopped by SIGTERM)' in a['incomplete']
    else:
        assert a['end_reason'] in ('ABORT', 'FALLEN') and not a['incomplete']   # no controller: it falls
    sim = json.loads((tmp_path / 'run' / 'sim_result.json').read_text())
    assert sim['end_reason'] in ('ABORT', 'FALLEN')
