"""The compiled MCAP/CDR scanner of bagread against the values written, without ROS.

The bag is written by mcap_ros2 (zstd chunks, messages of varying string lengths so that
every CDR alignment case occurs), with the message definitions of the ROS types.
"""
import json
import math
from pathlib import Path

import numpy as np
from mcap_ros2.writer import Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from ipfric_core.analysis.bagread import read_run

ROOT = Path(__file__).resolve().parents[2]


def msgdef(name):
    store = get_typestore(Stores.ROS2_KILTED)
    types = {}
    for f in sorted((ROOT / 'src' / 'ipfric_msgs' / 'msg').glob('*.msg')):
        types.update(get_types_from_msg(f.read_text(), f'ipfric_msgs/msg/{f.stem}'))
    store.register(types)
    return store.generate_msgdef(name, ros_version=2)[0]


def stamp(t):
    return {'sec': int(t), 'nanosec': int(round((t - int(t)) * 1e9))}


def write_bag(path, n):
    rng = np.random.default_rng(3)
    truth = rng.normal(size=(n, 6))
    with open(path, 'wb') as fh:
        w = Writer(fh, chunk_size=4096)
        js = w.register_msgdef('sensor_msgs/msg/JointState', msgdef('sensor_msgs/msg/JointState'))
        vc = w.register_msgdef('ipfric_msgs/msg/VoltageCommand', msgdef('ipfric_msgs/msg/VoltageCommand'))
        ps = w.register_msgdef('ipfric_msgs/msg/PlantState', msgdef('ipfric_msgs/msg/PlantState'))
        ev = w.register_msgdef('ipfric_msgs/msg/SafetyEvent', msgdef('ipfric_msgs/msg/SafetyEvent'))
        for k in range(n):
            t = 1e-3 * k
            head = {'stamp': stamp(t), 'frame_id': 'f' * (k % 5)}
            w.write_message('joint_states', js, {'header': head, 'name': ['cart' + 'x' * (k % 3), 'pendulum'],
                                                 'position': [0.001 * k, -0.002 * k], 'velocity': [],
                                                 'effort': [1.0] * (k % 2)}, log_time=k)
            w.write_message('voltage_command', vc, {'header': head, 'voltage': math.sin(k),
                                                    'measurement_stamp': stamp(t), 'sample_index': k}, log_time=k)
            w.write_message('plant_state', ps, {'header': head, **dict(zip(
                ('x', 'theta', 'x_dot', 'theta_dot', 'friction_force', 'z'), truth[k])), 'stuck': k % 4 == 0,
                'voltage_applied': -float(k), 'sample_index': k}, log_time=k)
        w.write_message('safety_event', ev, {'header': {'stamp': stamp(0.5), 'frame_id': ''}, 'code': 'END',
                                             'detail': 'done', 'sample_index': n}, log_time=n)
        w._writer.add_metadata('ipfric', {'ipfric.config': json.dumps({'sim': {'theta0': 0.02}})})
        w.finish()
    return truth


def test_scanner_reads_what_was_written(tmp_path):
    n = 300
    truth = write_bag(tmp_path / 'run.mcap', n)
    r = read_run(tmp_path / 'run.mcap')
    k = np.arange(n)
    np.testing.assert_allclose(r.t, 1e-3 * k, atol=1e-12)
    np.testing.assert_array_equal(r.x, 0.001 * k)
    np.testing.assert_array_equal(r.theta, -0.002 * k)
    np.testing.assert_array_equal(r.voltage, np.sin(k))
    np.testing.assert_allclose(r.command_t, 1e-3 * k, atol=1e-12)
    for i, f in enumerate(('x', 'theta', 'x_dot', 'theta_dot', 'friction_force', 'z')):
        np.testing.assert_array_equal(r.truth[f], truth[:, i])
    np.testing.assert_array_equal(r.truth['stuck'], (k % 4 == 0).astype(float))
    np.testing.assert_array_equal(r.truth['voltage_applied'], -k.astype(float))
    assert r.events == [(0.5, 'END', 'done')] and r.end_reason == 'END'
    assert r.config == {'sim': {'theta0': 0.02}} and not r.truncated
    assert r.counts == {'/joint_states': n, '/voltage_command': n, '/plant_state': n, '/safety_event': 1}


def test_a_file_cut_short_is_read_up_to_its_last_complete_chunk(tmp_path):
    write_bag(tmp_path / 'run.mcap', 300)
    data = (tmp_path / 'run.mcap').read_bytes()
    (tmp_path / 'cut.mcap').write_bytes(data[:len(data) // 2])
    r = read_run(tmp_path / 'cut.mcap')
    assert r.truncated and r.truncation_detail
    assert 50 < len(r.t) < 300
    np.testing.assert_array_equal(r.x, 0.001 * np.arange(len(r.t)))
