"""The stock ROS 2 command line against the project, as a lab uses it: ``ros2 launch`` of the
shipped launch file and ``ros2 run`` of the nodes as the README shows them record the same bag
as ``./ipfric run``; two namespaced rigs share a domain; a Ctrl-C of a launch records ABORT.

Uses the stock ROS 2 command line of ``../shared/ros2-clients`` (installed into
``ros2_ws/clients``, about 20 s once); skipped when it is absent.
"""
import os
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

from ipfric_core.analysis.bagread import read_run
from ipfric_core.constants import REPO_ROOT as ROOT
from ipfric_core.run.runner import claim_domain, ros_environment, run
from ipfric_core.run.scenario import SECTION_KEYS

pytestmark = pytest.mark.ros

CLIENTS = ROOT.parent / 'shared' / 'ros2-clients'
DURATION = 2.0
N = int(DURATION * 1000) + 1


@pytest.fixture(scope='module')
def ros2_env(tmp_path_factory):
    """The environment of a stock install: the wheels, the ros2 CLI and launch, the workspace, a
    ROS domain of its own (held for the module)."""
    if not (CLIENTS / 'install.sh').exists():
        pytest.skip(f'{CLIENTS} absent: no stock ros2 command line to test against')
    target = ROOT / 'ros2_ws' / 'clients'
    lock = claim_domain()
    env = ros_environment(lock.domain)
    subprocess.run(['bash', str(CLIENTS / 'install.sh'), str(target)], env=env, check=True,
                   capture_output=True)
    script = (f'source "{target}/env.sh" && source "{ROOT}/ros2_ws/install/setup.bash" && env -0')
    out = subprocess.run(['bash', '-c', script], env=env, capture_output=True, check=True).stdout.decode()
    env = dict(item.split('=', 1) for item in out.split('\0') if '=' in item)
    env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    env['ROS_LOG_DIR'] = str(tmp_path_factory.mktemp('roslog'))
    yield env
    subprocess.run(['ros2', 'daemon', 'stop'], env=env, capture_output=True, timeout=60)
    lock.release()


def scenario(tmp: Path, name: str = 'default', duration: float = DURATION) -> Path:
    """A user's scenario file: config/<name>.yaml with another duration."""
    text = (ROOT / 'config' / f'{name}.yaml').read_text()
    path = tmp / f'{name}_{duration:g}s.yaml'
    path.write_text(text.replace('    duration: 20.0 ', f'    duration: {duration} ', 1))
    assert f'duration: {duration} ' in path.read_text()
    return path


def ros2_run(env, out: Path, params: Path, order, namespace=()) -> dict:
    """The README's three `ros2 run` commands, with their defaults, started in ``order``; the simulator
    ends the run, then controller and recorder get Ctrl-C. The logs by node."""
    out.mkdir(parents=True)
    commands = {
        'recorder': ['ros2', 'run', 'ipfric_record', 'recorder', '--ros-args', *namespace,
                     '-p', f'output:={out / "bag"}', '-p', f'scenario_file:={params}'],
        'controller_node': ['ros2', 'run', 'ipfric_controller', 'controller_node', '--ros-args', *namespace,
                            '--params-file', str(params)],
        'sim_node': ['ros2', 'run', 'ipfric_sim', 'sim_node', '--ros-args', *namespace, '--params-file', str(params)],
    }
    procs = {}
    try:
        for name in order:
            procs[name] = subprocess.Popen(commands[name], env=env, stdout=open(out / f'{name}.log', 'w'),
                                           stderr=subprocess.STDOUT, start_new_session=True)
            time.sleep(1.0)                  # shells started one after the other (any order works)
        assert procs['sim_node'].wait(timeout=180) == 0, (out / 'sim_node.log').read_text()[-3000:]
        for name in ('controller_node', 'recorder'):
            os.killpg(procs[name].pid, signal.SIGINT)
            assert procs[name].wait(timeout=30) == 0, (out / f'{name}.log').read_text()[-3000:]
    finally:
        for p in procs.values():
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()
    return {name: (out / f'{name}.log').read_text() for name in commands}


def launch(env, *args) -> subprocess.Popen:
    return subprocess.Popen(['ros2', 'launch', 'ipfric_bringup', 'ipfric.launch.py', *args], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True)


@pytest.fixture(scope='module')
def bags(ros2_env, tmp_path_factory):
    """Bags of the same scenario by ./ipfric run, ros2 launch (scenario by name) and ros2 run as the
    README shows it, in its order and in the reverse one."""
    tmp = tmp_path_factory.mktemp('bringup')
    params = scenario(tmp)
    res = run(params, tmp / 'ipfric', timeout=120)
    assert res.exit_code == 0, res.summary()
    p = launch(ros2_env, 'scenario:=default', f'out:={tmp / "launch"}', f'duration:={DURATION}')
    out = p.communicate(timeout=180)[0]
    assert p.returncode == 0, out[-3000:]
    ros2_run(ros2_env, tmp / 'readme', params, ['recorder', 'controller_node', 'sim_node'])
    ros2_run(ros2_env, tmp / 'reverse', params, ['sim_node', 'controller_node', 'recorder'])
    return {'ipfric run': read_run(res.bag), 'ros2 launch': read_run(tmp / 'launch' / 'bag'),
            'ros2 run': read_run(tmp / 'readme' / 'bag'), 'ros2 run, reverse order': read_run(tmp / 'reverse' / 'bag')}


def test_the_ways_of_starting_record_the_same_bag(bags):
    ref = bags['ipfric run']
    assert ref.counts == {'/clock': N, '/joint_states': N, '/plant_state': N, '/voltage_command': N,
                          '/safety_event': 2, '/controller_gain': 1, '/diagnostics': 2, '/parameter_events': 0}
    np.testing.assert_allclose(ref.t, np.arange(N) / 1000.0, rtol=0, atol=1e-12)   # simulated time
    for how, bag in bags.items():
        assert bag.counts == ref.counts, how
        assert bag.intact and not bag.incomplete and bag.end_reason == 'END', how
        assert [code for _, code, _ in bag.events] == ['START', 'END'], how      # from sample 0 to the end
        # lockstep is deterministic: the same trajectory and commands, sample for sample
        for field in ('t', 'x', 'theta', 'command_t', 'voltage'):
            np.testing.assert_array_equal(getattr(bag, field), getattr(ref, field), err_msg=f'{how}: {field}')
        for k, v in ref.truth.items():
            np.testing.assert_array_equal(bag.truth[k], v, err_msg=f'{how}: truth {k}')
        assert bag.config == ref.config and bag.config['sim']['duration'] == DURATION, how


def test_command_header_stamps_are_simulated_time(bags):
    """use_sim_time of the scenario file: the controller stamps in the rig's simulated time."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore
    for how, bag in bags.items():
        path = Path(bag.path)
        with AnyReader([path], default_typestore=get_typestore(Stores.ROS2_KILTED)) as r:
            assert {c.topic for c in r.connections} == set(bag.counts), how
            conn = [c for c in r.connections if c.topic == '/voltage_command']
            stamps = [r.deserialize(raw, c.msgtype).header.stamp for c, _, raw in r.messages(connections=conn)]
        t = np.array([s.sec + 1e-9 * s.nanosec for s in stamps])
        np.testing.assert_array_equal(t, bag.command_t, err_msg=how)


def test_two_rigs_by_launch_and_ros2_run_share_a_domain(ros2_env, tmp_path):
    """/rig1 by ros2 launch (Figure 7 by name), /rig2 by ros2 run -r __ns:=/rig2 (Figure 9, the
    scenario file as it is shipped, keyed /**/node) in one domain at once: each bag is its rig's."""
    params = scenario(tmp_path, 'fig9_new_gain_exponential', 3.0)
    p = launch(ros2_env, 'scenario:=fig7_old_gain_exponential', 'namespace:=rig1', f'out:={tmp_path / "rig1"}',
               'duration:=4')
    try:
        ros2_run(ros2_env, tmp_path / 'rig2', params, ['recorder', 'controller_node', 'sim_node'],
                 ['-r', '__ns:=/rig2'])
        out = p.communicate(timeout=180)[0]
    finally:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
    assert p.returncode == 0, out[-3000:]
    for ns, n, gain in (('/rig1', 4001, [70.7107, 142.5409, 50.6911, 26.9817]),
                        ('/rig2', 3001, [70.7107, 304.9273, 143.3152, 61.0833])):
        bag = read_run(tmp_path / ns.strip('/') / 'bag')
        assert bag.namespace == ns and bag.gain == gain and bag.config['gain'] == gain
        assert bag.intact and not bag.incomplete and bag.end_reason == 'END'
        assert all(t.startswith(ns + '/') for t in bag.counts if t != '/parameter_events'), bag.counts
        assert bag.counts[f'{ns}/joint_states'] == bag.counts[f'{ns}/clock'] == len(bag.t) == n


def test_a_refused_launch_writes_nothing(ros2_env, tmp_path):
    p = launch(ros2_env, 'scenario:=default', f'out:={tmp_path / "x"}', 'theta0:=3.0')
    out = p.communicate(timeout=120)[0]
    assert p.returncode != 0 and 'theta0' in out
    assert not (tmp_path / 'x').exists()


@pytest.mark.slow
@pytest.mark.long
def test_ctrl_c_of_a_launch_records_abort_before_the_bag_closes(ros2_env, tmp_path):
    """Ctrl-C in the terminal of `ros2 launch` (SIGINT to the whole process group, every node at
    once), 10 times: each bag ends with ABORT and is whole."""
    for i in range(10):
        out = tmp_path / f'try{i}'
        p = launch(ros2_env, 'scenario:=default', f'out:={out}', 'duration:=0')
        try:
            log = out / 'bag'
            t0 = time.monotonic()
            while not (log.exists() and read_bag_started(log)):
                assert p.poll() is None and time.monotonic() - t0 < 120, 'the launch did not start'
                time.sleep(0.2)
            time.sleep(0.5)
            os.killpg(p.pid, signal.SIGINT)
            text = p.communicate(timeout=60)[0]
        finally:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)
        bag = read_run(out / 'bag')
        assert bag.intact and bag.end_reason == 'ABORT' and not bag.incomplete, (i, text[-2000:])
        assert 'stopped by SIGINT' in bag.events[-1][2]


def read_bag_started(bag: Path) -> bool:
    """Whether the recorder has written its first chunk (the run is going)."""
    files = list(bag.glob('*.mcap'))
    return bool(files) and files[0].stat().st_size > 70_000


def test_the_installed_scenarios_urdf_and_layouts(ros2_env):
    share = Path(subprocess.run(['ros2', 'pkg', 'prefix', '--share', 'ipfric_bringup'], env=ros2_env,
                                capture_output=True, text=True, check=True).stdout.strip())
    names = sorted(p.stem for p in (share / 'config').glob('*.yaml'))
    assert names == sorted(p.stem for p in (ROOT / 'config').glob('*.yaml') if p.name != 'paper.yaml')
    assert (share / 'urdf' / 'cart_pendulum.urdf').is_file() and (share / 'rviz' / 'ipfric.rviz').is_file()
    text = (share / 'config' / 'default.yaml').read_text()
    assert SECTION_KEYS['sim_node'] + ':' in text
    shown = subprocess.run(['ros2', 'launch', 'ipfric_bringup', 'ipfric.launch.py', '--show-args'], env=ros2_env,
                           capture_output=True, text=True, timeout=60).stdout
    for arg in ('scenario', 'out', 'namespace', 'robot_state_publisher', 'duration', 'time_mode', 'theta0', 'delay'):
        assert f"'{arg}'" in shown, shown
