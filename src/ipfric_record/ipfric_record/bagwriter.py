"""A rosbag2 directory with MCAP storage, written with the ``mcap`` library (no ROS).

Layout as ``ros2 bag record -s mcap`` writes it (rosbag2 format version 9):

- ``<dir>/<dir name>_0.mcap``: profile ``ros2``; one schema per message type (encoding
  ``ros2msg``, the .msg text with its dependencies as rosbag2 concatenates them); one
  channel per fully qualified topic name (message encoding ``cdr``, channel metadata
  ``offered_qos_profiles`` and ``topic_type_hash``, the type's RIHS01 hash);
  chunked messages with message indexes; a summary with Statistics, chunk indexes and a
  metadata index; metadata records ``rosbag2`` (``serialized_metadata``, the bag
  information as YAML) and, here, ``ipfric`` (the run configuration).
- ``<dir>/metadata.yaml``: the same bag information, written at close.

Message definitions and RIHS01 type hashes come from a :mod:`rosbags` typestore; the
hashes of the standard and ipfric_msgs types equal those ROS computes.
"""
from __future__ import annotations

from pathlib import Path

import yaml
from mcap.writer import CompressionType, Writer

ROS_DISTRO = 'kilted'


CHUNK_BYTES = 64 * 1024

class _Dumper(yaml.SafeDumper):
    """No anchors/aliases: every mapping written out in full, as rosbag2 does."""

    def ignore_aliases(self, data):
        return True


def _yaml(data) -> str:
    return yaml.dump(data, Dumper=_Dumper, sort_keys=False)


def qos_dict(reliable: bool = True, depth: int = 1000, transient_local: bool = False) -> dict:
    """An offered QoS profile in rosbag2's (version 9) form."""
    zero = {'sec': 0, 'nsec': 0}
    return {'history': 'keep_last', 'depth': depth, 'reliability': 'reliable' if reliable else 'best_effort',
            'durability': 'transient_local' if transient_local else 'volatile',
            'deadline': zero, 'lifespan': zero, 'liveliness': 'automatic',
            'liveliness_lease_duration': zero, 'avoid_ros_namespace_conventions': False}


class BagWriter:
    """Write serialized (CDR) messages of several topics into a new rosbag2 MCAP directory.

    Parameters
    ----------
    path : the bag directory; it must not exist
    typestore : rosbags Typestore knowing every message type written
    custom_data : str -> str, stored in metadata.yaml ``custom_data`` and in the MCAP
        ``rosbag2`` record
    metadata : name -> (str -> str), extra MCAP metadata records
    """

    def __init__(self, path, typestore, custom_data: dict | None = None, metadata: dict | None = None):
        self.path = Path(path)
        if self.path.exists():
            raise FileExistsError(f'{self.path} exists already; not overwriting')
        self.path.mkdir(parents=True)
        self.file = self.path / f'{self.path.name}_0.mcap'
        self.store = typestore
        self.custom_data = dict(custom_data or {})
        self.metadata = dict(metadata or {})
        self._fh = open(self.file, 'wb')
        # 64 KiB chunks with CRCs: a recorder killed mid-run, or a damaged byte, loses a fraction of a second
        self._mcap = Writer(self._fh, chunk_size=CHUNK_BYTES, compression=CompressionType.NONE,
                            enable_crcs=True, enable_data_crcs=True)
        self._mcap.start(profile='ros2', library='ipfric_record (mcap python)')
        self._schemas: dict[str, int] = {}
        self.topics: dict[str, dict] = {}   # topic -> {id, type, qos, count, hash}
        self.start_ns: int | None = None
        self.end_ns: int | None = None
        self.closed = False

    def add_topic(self, topic: str, msgtype: str, qos: dict) -> int:
        """Register a topic (fully qualified, e.g. '/joint_states') of ROS type ``msgtype``
        (e.g. 'sensor_msgs/msg/JointState')."""
        if not topic.startswith('/'):
            raise ValueError(f'topic {topic!r}: give the fully qualified name ("/{topic}"), as rosbag2 records it')
        if msgtype not in self._schemas:
            msgdef, _ = self.store.generate_msgdef(msgtype, ros_version=2)
            self._schemas[msgtype] = self._mcap.register_schema(msgtype, 'ros2msg', msgdef.encode())
        type_hash = self.store.hash_rihs01(msgtype)
        cid = self._mcap.register_channel(topic, 'cdr', self._schemas[msgtype],
                                          {'offered_qos_profiles': _yaml([qos]).strip(),
                                           'topic_type_hash': type_hash})
        self.topics[topic] = {'id': cid, 'type': msgtype, 'qos': qos, 'count': 0, 'hash': type_hash}
        return cid

    def write(self, topic: str, time_ns: int, data) -> None:
        """Append one serialized message received at ``time_ns``."""
        t = self.topics[topic]
        self._mcap.add_message(t['id'], time_ns, bytes(data), time_ns, t['count'])
        t['count'] += 1
        if self.start_ns is None or time_ns < self.start_ns:
            self.start_ns = time_ns
        if self.end_ns is None or time_ns > self.end_ns:
            self.end_ns = time_ns

    def info(self) -> dict:
        """The rosbag2_bagfile_information mapping (metadata.yaml)."""
        start = self.start_ns or 0
        duration = (self.end_ns - start) if self.end_ns is not None else 0
        count = sum(t['count'] for t in self.topics.values())
        return {
            'version': 9,
            'storage_identifier': 'mcap',
            'duration': {'nanoseconds': duration},
            'starting_time': {'nanoseconds_since_epoch': start},
            'message_count': count,
            'topics_with_message_count': [
                {'topic_metadata': {'name': name, 'type': t['type'], 'serialization_format': 'cdr',
                                    'offered_qos_profiles': [t['qos']], 'type_description_hash': t['hash']},
                 'message_count': t['count']}
                for name, t in self.topics.items()],
            'compression_format': '',
            'compression_mode': '',
            'relative_file_paths': [self.file.name],
            'files': [{'path': self.file.name, 'starting_time': {'nanoseconds_since_epoch': start},
                       'duration': {'nanoseconds': duration}, 'message_count': count}],
            'custom_data': self.custom_data or None,
            'ros_distro': ROS_DISTRO,
        }

    def counts(self) -> dict:
        return {name: t['count'] for name, t in self.topics.items()}

    def close(self) -> None:
        """Write the metadata records and the summary, then metadata.yaml."""
        if self.closed:
            return
        info = self.info()
        for name, data in self.metadata.items():
            self._mcap.add_metadata(name, data)
        self._mcap.add_metadata('rosbag2', {'serialized_metadata': _yaml(info)})
        self._mcap.finish()
        self._fh.close()
        tmp = self.path / 'metadata.yaml.tmp'
        tmp.write_text(_yaml({'rosbag2_bagfile_information': info}))
        tmp.replace(self.path / 'metadata.yaml')
        self.closed = True
