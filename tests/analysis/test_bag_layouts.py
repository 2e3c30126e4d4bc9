"""Bags of both layouts read alike: rosbag2's (``bag_0.mcap``, ``/joint_states``) and the
older one of this project (``bag.mcap``, ``joint_states``)."""
import json

import numpy as np
import pytest
from mcap_ros2.writer import Writer
from rosbags.typesys import Stores, get_typestore

from ipfric_core.analysis.bagread import read_run

STORE = get_typestore(Stores.ROS2_KILTED)
SAFETY = 'string code\nstring detail\nuint64 sample_index'   # only the fields read; header first


def write_run(run_dir, file_name, prefix, n=200):
    """A run directory with a bag of ``n`` joint states and one END event."""
    bag = run_dir / 'bag'
    bag.mkdir(parents=True)
    (bag / 'metadata.yaml').write_text('rosbag2_bagfile_information: {version: 9}\n')
    js_def = STORE.generate_msgdef('sensor_msgs/msg/JointState', ros_version=2)[0]
    header_def = STORE.generate_msgdef('std_msgs/msg/Header', ros_version=2)[0]
    ev_def = ('std_msgs/Header header\n' + SAFETY + '\n' + '=' * 80 + '\nMSG: std_msgs/Header\n' + header_def)
    with open(bag / file_name, 'wb') as fh:
        w = Writer(fh)
        js = w.register_msgdef('sensor_msgs/msg/JointState', js_def)
        ev = w.register_msgdef('ipfric_msgs/msg/SafetyEvent', ev_def)
        for k in range(n):
            stamp = {'sec': k // 1000, 'nanosec': (k % 1000) * 1_000_000}
            w.write_message(prefix + 'joint_states', js, {'header': {'stamp': stamp, 'frame_id': ''},
                                                          'name': ['cart', 'pendulum'],
                                                          'position': [1e-4 * k, -2e-4 * k],
                                                          'velocity': [], 'effort': []}, log_time=k)
        w.write_message(prefix + 'safety_event', ev, {'header': {'stamp': {'sec': 0, 'nanosec': 199_000_000},
                                                                 'frame_id': ''}, 'code': 'END',
                                                      'detail': 'duration', 'sample_index': n}, log_time=n)
        w.finish()


@pytest.mark.parametrize('file_name, prefix', [('bag_0.mcap', '/'), ('bag.mcap', '')], ids=['rosbag2', 'old'])
def test_both_layouts_give_the_same_run(tmp_path, file_name, prefix):
    write_run(tmp_path / 'run', file_name, prefix)
    k = np.arange(200)
    for path in (tmp_path / 'run', tmp_path / 'run' / 'bag', tmp_path / 'run' / 'bag' / file_name):
        r = read_run(path)
        np.testing.assert_allclose(r.t, 1e-3 * k, atol=1e-12)
        np.testing.assert_array_equal(r.x, 1e-4 * k)
        np.testing.assert_array_equal(r.theta, -2e-4 * k)
        assert r.events == [(0.199, 'END', 'duration')] and r.end_reason == 'END'
        assert r.counts == {'/joint_states': 200, '/safety_event': 1}


def test_analysis_reports_the_loop_timing_of_a_run(tmp_path):
    """Stale samples (no fresh command at the deadline) and latency from sim_result.json."""
    from ipfric_core.analysis.recorded_run import analyze_run
    write_run(tmp_path / 'run', 'bag_0.mcap', '/')
    assert 'samples_without_command' not in analyze_run(tmp_path / 'run')
    latency = {'commands': 199, 'median': 3e-4, 'p99': 1.4e-3, 'max': 0.037}
    (tmp_path / 'run' / 'sim_result.json').write_text(json.dumps(
        {'time_mode': 'realtime', 'samples_without_command': 3, 'command_latency_s': latency}))
    for path in (tmp_path / 'run', tmp_path / 'run' / 'bag', tmp_path / 'run' / 'bag' / 'bag_0.mcap'):
        a = analyze_run(path)
        assert (a['time_mode'], a['samples_without_command'], a['command_latency_s']) == ('realtime', 3, latency)
