"""The recorder's bag layout against rosbag2's: file name, topic names, channel metadata,
metadata.yaml (compared with the rosbag2 Writer of rosbags), readable by rosbags.

rosbag2's MCAP storage plugin writes the channel metadata ``offered_qos_profiles`` and
``topic_type_hash`` (the RIHS01 hash it reads back when metadata.yaml is missing) and
names the first file ``<bag>_0.mcap``.
"""
import pytest
import yaml
from mcap.reader import make_reader
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

bagwriter = pytest.importorskip('ipfric_record.bagwriter', reason='ros2_ws not built (bash scripts/setup.sh)')

JS = 'sensor_msgs/msg/JointState'
CDR = bytes.fromhex('00010000') + bytes(16)   # a JointState with empty header and arrays


def write_ours(path, store):
    w = bagwriter.BagWriter(path, store, custom_data={'k': 'v'})
    w.add_topic('/joint_states', JS, bagwriter.qos_dict())
    for t in (5, 9):
        w.write('/joint_states', t, CDR)
    w.close()


def write_rosbags(path, store):
    w = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP)
    w.open()
    c = w.add_connection('/joint_states', JS, typestore=store)
    for t in (5, 9):
        w.write(c, t, CDR)
    w.close()


def info(path):
    return yaml.safe_load((path / 'metadata.yaml').read_text())['rosbag2_bagfile_information']


def test_bag_has_rosbag2_layout_names_and_type_hash(tmp_path):
    store = get_typestore(Stores.ROS2_KILTED)
    ours, ref = tmp_path / 'bag', tmp_path / 'ref' / 'bag'
    write_ours(ours, store)
    write_rosbags(ref, store)
    assert sorted(p.name for p in ours.iterdir()) == ['bag_0.mcap', 'metadata.yaml']
    a, b = info(ours), info(ref)
    assert set(a) == set(b) and a['version'] == 9 and a['storage_identifier'] == 'mcap'
    ta, tb = (x['topics_with_message_count'][0] for x in (a, b))
    assert set(ta['topic_metadata']) == set(tb['topic_metadata'])
    for k in ('name', 'type', 'serialization_format', 'type_description_hash'):
        assert ta['topic_metadata'][k] == tb['topic_metadata'][k]
    assert ta['message_count'] == tb['message_count'] == 2
    assert a['relative_file_paths'] == ['bag_0.mcap'] and a['files'][0]['path'] == 'bag_0.mcap'
    assert (a['starting_time'], a['duration']) == (b['starting_time'], b['duration'])
    with open(ours / 'bag_0.mcap', 'rb') as f:
        ch = next(iter(make_reader(f).get_summary().channels.values()))
    assert ch.topic == '/joint_states'
    assert ch.metadata['topic_type_hash'] == ta['topic_metadata']['type_description_hash']
    assert ch.metadata['topic_type_hash'].startswith('RIHS01_') and len(ch.metadata['topic_type_hash']) == 71
    assert yaml.safe_load(ch.metadata['offered_qos_profiles'])[0]['reliability'] == 'reliable'
    with AnyReader([ours], default_typestore=store) as r:
        assert [(c.topic, c.msgcount) for c in r.connections] == [('/joint_states', 2)]


def test_relative_topic_names_are_refused(tmp_path):
    w = bagwriter.BagWriter(tmp_path / 'bag', get_typestore(Stores.ROS2_KILTED))
    with pytest.raises(ValueError, match='fully qualified'):
        w.add_topic('joint_states', JS, bagwriter.qos_dict())
    w.close()
