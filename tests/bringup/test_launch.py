"""``ros2 launch`` of the shipped launch file and ``ros2 run`` of the nodes record the same
bag as ``./ipfric run``: message counts, stamps in simulated time, fully qualified topics.

Uses the stock ROS 2 command line of ``../shared/ros2-clients`` (installed into
``ros2_ws/clients``, about 20 s once); skipped when it is absent.
"""
import os
import signal
import subprocess
from pathlib import Path

import numpy as np
import pytest

from ipfric_core.analysis.bagread import read_run
from ipfric_core.constants import REPO_ROOT as ROOT
from ipfric_core.run.nodes import NODES, node_parameters, ros_args, write_run_scenario
from ipfric_core.run.runner import pick_domain, ros_environment, run

pytestmark = pytest.mark.ros

CLIENTS = ROOT.parent / 'shared' / 'ros2-clients'
DURATION = 2.0
N = int(DURATION * 1000) + 1


@pytest.fixture(scope='module')
def ros2_env(tmp_path_factory):
    """The environment of a stock install: the wheels, the ros2 CLI and launch, the workspace."""
    if not (CLIENTS / 'install.sh').exists():
        pytest.skip(f'{CLIENTS} absent: no stock ros2 command line to test against')
    target = ROOT / 'ros2_ws' / 'clients'
    env = ros_environment(pick_domain())
    subprocess.run(['bash', str(CLIENTS / 'install.sh'), str(target)], env=env, check=True,
                   capture_output=True)
    script = (f'source "{target}/env.sh" && source "{ROOT}/ros2_ws/install/setup.bash" && env -0')
    out = subprocess.run(['bash', '-c', script], env=env, capture_output=True, check=True).stdout.decode()
    env = dict(item.split('=', 1) for item in out.split('\0') if '=' in item)
    env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    env['ROS_LOG_DIR'] = str(tmp_path_factory.mktemp('roslog'))
    yield env
    subprocess.run(['ros2', 'daemon', 'stop'], env=env, capture_output=True, timeout=60)


@pytest.fixture(scope='module')
def bags(ros2_env, tmp_path_factory):
    """Bags of the same scenario by ./ipfric run, ros2 launch and ros2 run."""
    tmp = tmp_path_factory.mktemp('bringup')
    config = ROOT / 'config' / 'default.yaml'
    res = run(config, tmp / 'ipfric', duration=DURATION, timeout=120)
    assert res.exit_code == 0, res.summary()
    launch = subprocess.run(['ros2', 'launch', 'ipfric_bringup', 'ipfric.launch.py', f'scenario:={config}',
                             f'out:={tmp / "launch"}', f'duration:={DURATION}'],
                            env=ros2_env, capture_output=True, text=True, timeout=180)
    assert launch.returncode == 0, launch.stdout[-3000:] + launch.stderr[-3000:]
    out = tmp / 'ros2run'
    scenario = write_run_scenario(config, out, {'duration': DURATION})
    params = node_parameters(scenario, out)
    del params['controller_node'][1]['use_sim_time']      # from the scenario file alone
    procs = {}
    for name, (package, executable) in NODES.items():
        log = open(out / f'{name}.log', 'w')
        procs[name] = subprocess.Popen(['ros2', 'run', package, executable, '--ros-args',
                                        *ros_args(*params[name])], env=ros2_env, stdout=log,
                                       stderr=subprocess.STDOUT, start_new_session=True)
    try:
        assert procs['sim_node'].wait(timeout=120) == 0, (out / 'sim_node.log').read_text()[-3000:]
        for name in ('controller_node', 'recorder'):
            os.killpg(procs[name].pid, signal.SIGINT)
            assert procs[name].wait(timeout=30) == 0, (out / f'{name}.log').read_text()[-3000:]
    finally:
        for p in procs.values():
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()
    return {'ipfric run': read_run(res.bag), 'ros2 launch': read_run(tmp / 'launch' / 'bag'),
            'ros2 run': read_run(out / 'bag')}


def test_the_three_ways_record_the_same_bag(bags):
    ref = bags['ipfric run']
    assert ref.counts == {'/clock': N, '/joint_states': N, '/plant_state': N, '/voltage_command': N,
                          '/safety_event': 2, '/controller_gain': 1}
    np.testing.assert_allclose(ref.t, np.arange(N) / 1000.0, rtol=0, atol=1e-12)   # simulated time
    for how, bag in bags.items():
        assert bag.counts == ref.counts, how
        assert not bag.truncated and bag.end_reason == 'END', how
        # lockstep is deterministic: the same trajectory and commands, sample for sample
        for field in ('t', 'x', 'theta', 'command_t', 'voltage'):
            np.testing.assert_array_equal(getattr(bag, field), getattr(ref, field), err_msg=f'{how}: {field}')
        assert bag.config['sim']['duration'] == DURATION, how


def test_command_header_stamps_are_simulated_time(bags):
    """use_sim_time of the scenario file: the controller stamps with sim_node's /clock."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore
    for how, bag in bags.items():
        path = Path(bag.path)
        with AnyReader([path], default_typestore=get_typestore(Stores.ROS2_KILTED)) as r:
            assert {c.topic for c in r.connections} == set(bag.counts), how
            conn = [c for c in r.connections if c.topic == '/voltage_command']
            stamps = [r.deserialize(raw, c.msgtype).header.stamp for c, _, raw in r.messages(connections=conn)]
        t = np.array([s.sec + 1e-9 * s.nanosec for s in stamps])
        assert len(t) == N and t.max() <= DURATION + 0.01, f'{how}: header stamps up to {t.max()} s'
