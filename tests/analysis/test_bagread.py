"""The compiled MCAP/CDR scanner of bagread against the values written, without ROS.

The bag is written by mcap_ros2 (zstd chunks, messages of varying string lengths so that
every CDR alignment case occurs), with the message definitions of the ROS types.
"""
import json
import math
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap.writer import CompressionType
from mcap_ros2.writer import Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from ipfric_core.analysis.bagread import read_run
from ipfric_core.cli import main
from ipfric_core.physics.params import ConfigError

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


def write_bag(path, n, crcs=True, theta=None):
    """A bag of ``n`` samples; ``theta`` replaces plant_state.theta of sample n // 2."""
    rng = np.random.default_rng(3)
    truth = rng.normal(size=(n, 6))
    if theta is not None:
        truth[n // 2, 1] = theta
    with open(path, 'wb') as fh:
        w = Writer(fh, chunk_size=4096, enable_crcs=crcs,    # without CRCs: uncompressed, to be edited
                   compression=CompressionType.ZSTD if crcs else CompressionType.NONE)
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


def test_a_file_cut_short_keeps_the_records_of_its_incomplete_last_chunk(tmp_path):
    with open(tmp_path / 'run.mcap', 'wb') as fh:        # one uncompressed chunk, as the recorder writes
        w = Writer(fh, chunk_size=1 << 20, compression=CompressionType.NONE)
        js = w.register_msgdef('sensor_msgs/msg/JointState', msgdef('sensor_msgs/msg/JointState'))
        for k in range(1000):
            w.write_message('joint_states', js, {'header': {'stamp': stamp(1e-3 * k), 'frame_id': ''},
                                                 'name': ['cart', 'pendulum'], 'position': [k, -k],
                                                 'velocity': [], 'effort': []}, log_time=k)
        w.finish()
    data = (tmp_path / 'run.mcap').read_bytes()
    (tmp_path / 'cut.mcap').write_bytes(data[:len(data) // 2])
    r = read_run(tmp_path / 'cut.mcap')
    assert r.truncated and 'cut short' in r.truncation_detail
    assert 400 < len(r.t) < 600
    np.testing.assert_array_equal(r.x, np.arange(len(r.t)))


def test_a_string_length_pointing_outside_the_message_is_reported_not_followed(tmp_path):
    """The high byte of header.frame_id's length set in every plant_state (no CRCs to catch it)."""
    n = 200
    write_bag(tmp_path / 'run.mcap', n, crcs=False)
    data = bytearray((tmp_path / 'run.mcap').read_bytes())
    marker = bytes([0, 1, 0, 0])                     # CDR little-endian encapsulation
    with open(tmp_path / 'run.mcap', 'rb') as fh:
        channel = [c.id for c in make_reader(fh).get_summary().channels.values() if c.topic == 'plant_state']
    hits = 0
    for k in range(len(data) - 40):
        if data[k] == 5 and data[k + 9 + 22:k + 9 + 26] == marker and data[k + 9] == channel[0]:
            data[k + 9 + 26 + 8 + 3] = 0x80          # frame_id length += 2 GiB
            hits += 1
    assert hits == n
    (tmp_path / 'bad.mcap').write_bytes(bytes(data))
    r = read_run(tmp_path / 'bad.mcap')
    assert len(r.truth_t) == 0 and len(r.t) == n
    assert any(f'{n} message(s) did not decode or did not fit' in d for d in r.damage), r.damage
    assert main(['analyze', '--plots', str(tmp_path / 'plots'), '--json', str(tmp_path / 'bad.mcap')]) == 1
    assert read_run(tmp_path / 'bad.mcap', keep=('joint_states',)).intact   # plant_state not decoded


def test_absurd_values_are_dropped_and_reported(tmp_path):
    write_bag(tmp_path / 'run.mcap', 300, theta=2.1e304)
    r = read_run(tmp_path / 'run.mcap')
    assert len(r.truth_t) == 299 and np.abs(r.truth['theta']).max() < 10
    assert r.damage == ['plant_state: 1 message(s) with a value not finite or beyond |x| 1000, |theta| 10000, '
                        '|x_dot| 10000, |theta_dot| 1e+06, |friction_force| 1e+06, |z| 1000, |stuck| 1, '
                        '|voltage_applied| 1e+06 dropped, the first at t = 0.150 s']


@pytest.mark.parametrize('content, phrase', [
    (b'', 'not an MCAP file (it is empty'),
    (bytes(np.random.default_rng(1).integers(0, 256, 5000, dtype=np.uint8)), 'not an MCAP file (it starts with'),
    (b't,x,voltage\n0,0,1\n', "not an MCAP file (it starts with b't,x,volt'"),
])
def test_a_file_that_is_not_mcap_is_refused_with_exit_2(tmp_path, capsys, content, phrase):
    (tmp_path / 'x.mcap').write_bytes(content)
    with pytest.raises(ConfigError, match='give the bag directory or .mcap file of a run'):
        read_run(tmp_path / 'x.mcap')
    assert main(['analyze', '--no-plots', str(tmp_path / 'x.mcap')]) == 2
    assert phrase in capsys.readouterr().err


def test_identify_on_a_cut_bag_says_it_is_cut_and_what_is_missing(tmp_path, capsys):
    write_bag(tmp_path / 'run.mcap', 300)
    data = (tmp_path / 'run.mcap').read_bytes()
    (tmp_path / 'cut.mcap').write_bytes(data[:len(data) // 2])
    assert main(['identify', str(tmp_path / 'cut.mcap'), '--out', str(tmp_path / 'out'), '--no-plots']) == 2
    err = capsys.readouterr().err
    assert 'the bag is truncated (' in err and 'its scenario' in err and 'is cut off' in err, err
    assert 'plant constants are missing' in err and '--plant' in err and 'Traceback' not in err
