"""Bad parameters and a killed controller, with the real node processes."""
import json
import signal
import subprocess
import sys
import time

import pytest
from rosrun import scenario_file, start_node, started

from ipfric_core.analysis.bagread import read_run
from ipfric_core.constants import REPO_ROOT as ROOT
from ipfric_core.run.runner import Run, claim_domain


def refused(node: str, cfg, log) -> str:
    """The log of ``node`` started on parameter file ``cfg`` in a ROS domain held meanwhile (a run started
    beside it picks another); the node must exit with 2 within a minute (else it is killed)."""
    lock, p = claim_domain(), None
    try:
        p = start_node(node, ['--params-file', str(cfg)], lock.domain, log)
        assert p.wait(timeout=60) == 2
    finally:
        if p is not None and p.poll() is None:
            p.kill()
            p.wait()
        lock.release()
    return log.read_text()


@pytest.mark.parametrize('node, changes, field', [
    ('sim_node', {'sim': {'friction.model': 'bristle'}},
     "sim_node.ros__parameters.friction.model: 'bristle' is not one of viscous, coulomb, exponential, dynamic"),
    ('sim_node', {'sim': {'theta0': 3.5}}, 'sim_node.ros__parameters.theta0: 3.5 refused'),
    ('controller_node', {'controller': {'delay': 0.0015}},
     'controller_node.ros__parameters.delay: delay tau = 0.0015 s is not a multiple of the sample period'),
    ('controller_node', {'controller': {'gain_source': 'guess'}},
     "controller_node.ros__parameters.gain_source: 'guess' is not one of yaml, design"),
])
def test_bad_parameter_stops_the_node_naming_the_field(tmp_path, node, changes, field):
    cfg = scenario_file(tmp_path, 'fig7_old_gain_exponential.yaml', **changes)
    log = refused(node, cfg, tmp_path / f'{node}.log')
    assert '[FATAL]' in log and field in log, log


def test_unknown_parameter_is_named_with_a_suggestion(tmp_path):
    cfg = tmp_path / 'typo.yaml'
    cfg.write_text((ROOT / 'config' / 'fig7_old_gain_exponential.yaml').read_text()
                   .replace('    watchdog_samples:', '    watchdog_sample:'))
    log = refused('sim_node', cfg, tmp_path / 'sim.log')
    assert "unknown parameter(s) 'watchdog_sample' (did you mean 'watchdog_samples'?)" in log, log


def test_run_refuses_a_bad_scenario_before_starting_anything(tmp_path):
    cfg = scenario_file(tmp_path, 'fig7_old_gain_exponential.yaml', sim={'friction.model': 'bristle'})
    out = subprocess.run([sys.executable, '-m', 'ipfric_core.cli', 'run', '--config', str(cfg),
                          '--out', str(tmp_path / 'run')], capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 2
    assert "sim_node.ros__parameters.friction.model: 'bristle' is not one of" in out.stderr
    assert not (tmp_path / 'run' / 'logs').exists()


@pytest.mark.slow
def test_killed_controller_trips_the_watchdog_and_fails_the_run(tmp_path):
    # 50 samples x 0.05 s: a SIGKILLed peer stays in the DDS graph until its lease expires,
    # so the simulator waits the full timeout for each sample until the watchdog trips
    cfg = scenario_file(tmp_path, 'fig7_old_gain_exponential.yaml', sim={'lockstep_timeout_s': 0.05})
    r = Run(cfg, tmp_path / 'run', duration=20.0, timeout=120, grace=30.0)
    r.start()
    try:
        started(r.logs['sim_node'], r.procs['sim_node'])
        time.sleep(0.3)                   # mid-run (not a discovery wait)
        r.procs['controller_node'].kill()  # SIGKILL: no goodbye to the DDS graph
        res = r.wait()
    finally:
        r.kill()
    assert res.exit_code == 1
    assert any(f.startswith('controller_node killed by SIGKILL') for f in res.failures), res.failures
    bag = read_run(res.bag)               # readable: the recorder closed it
    assert not bag.truncated
    codes = [code for _, code, _ in bag.events]
    assert 'WATCHDOG' in codes
    assert bag.end_reason in ('FALLEN', 'TRACK_LIMIT'), codes   # 0 V held: the pendulum falls
    assert res.counts_match
    k_trip = [t for t, code, _ in bag.events if code == 'WATCHDOG'][0]
    # no command after the controller died: the last one answers the sample the watchdog trips at at most
    # (sent as it was killed, it reached the simulator after the 2 s stall: a late answer, not applied; seen once)
    assert bag.command_t[-1] <= k_trip
    # after the watchdog the rig applied 0 V
    after = bag.truth_t > k_trip + 1.5e-3
    assert (bag.truth['voltage_applied'][after] == 0.0).all()


@pytest.mark.slow
def test_ctrl_c_stops_the_run_and_keeps_a_readable_bag(tmp_path):
    out = tmp_path / 'run'
    p = subprocess.Popen([sys.executable, '-m', 'ipfric_core.cli', 'run', '--config',
                          str(ROOT / 'config' / 'default.yaml'), '--duration', '0', '--out', str(out),
                          '--json'], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    try:
        started(out / 'logs' / 'sim_node.log', p)
        time.sleep(0.5)                   # let it run a little
        p.send_signal(signal.SIGINT)      # Ctrl-C reaches the runner only (nodes have their own session)
        stdout, stderr = p.communicate(timeout=60)
    finally:
        if p.poll() is None:              # the runner's SIGTERM handler stops its nodes
            p.terminate()
            p.wait(timeout=60)
    assert p.returncode == 130, stderr
    res = json.loads(stdout)
    assert res['interrupted'] and res['end_reason'] == 'ABORT' and res['counts_match']
    assert set(res['exit_codes'].values()) == {0}
    bag = read_run(out / 'bag')
    assert not bag.truncated and bag.end_reason == 'ABORT'
    assert 'stopped by SIGINT' in bag.events[-1][2]
    assert len(bag.t) == res['samples'] > 100
    shown = subprocess.run([sys.executable, '-m', 'ipfric_core.cli', 'analyze', str(out), '--no-plots'],
                           capture_output=True, text=True, cwd=ROOT)
    assert 'end: ABORT (stopped by SIGINT' in shown.stdout, shown.stdout     # analyze says why the run ended
