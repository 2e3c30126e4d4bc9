"""Read an ipfric run back from its MCAP file, without a ROS runtime.

Accepts a rosbag2 directory (metadata.yaml + .mcap) or a bare .mcap file. Records are
streamed one by one (memory grows only with the arrays kept), decoded with the message
definitions stored in the file itself, and a file cut short (recorder killed) is read
up to its last complete record and reported as truncated.
"""
from __future__ import annotations

import json
import struct
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mcap.exceptions import McapError
from mcap.records import Channel, Message, Metadata, Schema
from mcap.stream_reader import StreamReader
from mcap_ros2.decoder import DecoderFactory

from .params import ConfigError


@dataclass
class RunData:
    """Arrays of one run (SI units); times are simulated time from header stamps [s]."""

    path: str
    t: np.ndarray                 # joint_states stamps
    x: np.ndarray                 # cart encoder [m]
    theta: np.ndarray             # angle encoder [rad]
    command_t: np.ndarray         # voltage_command measurement stamps
    voltage: np.ndarray           # [V]
    truth_t: np.ndarray
    truth: dict                   # x, theta, x_dot, theta_dot, friction_force, z, stuck, voltage_applied
    events: list                  # (t, code, detail)
    gain: list | None
    config: dict | None
    counts: dict = field(default_factory=dict)
    truncated: bool = False
    truncation_detail: str = ''

    @property
    def end_reason(self) -> str | None:
        for _, code, _ in reversed(self.events):
            if code in ('END', 'TRACK_LIMIT', 'FALLEN', 'ABORT'):
                return code
        return None


def mcap_file(path: str | Path) -> Path:
    """The .mcap of a rosbag2 directory or of a run directory (``bag/``), or ``path`` itself."""
    p = Path(path)
    if p.is_dir():
        files = sorted(p.glob('*.mcap')) or sorted(p.glob('bag/*.mcap'))  # a bag, or a run directory
        if not files:
            raise ConfigError(f'{p}: no .mcap file here or in {p}/bag (expected a rosbag2 directory, '
                              f'a run directory of ./ipfric run, or a .mcap file)')
        return files[0]
    if not p.exists():
        raise ConfigError(f'{p}: no such bag (give a rosbag2 directory or a .mcap file)')
    return p


def _stamp(h) -> float:
    return h.sec + 1e-9 * h.nanosec


TRUTH_FIELDS = ('x', 'theta', 'x_dot', 'theta_dot', 'friction_force', 'z', 'stuck', 'voltage_applied')


def read_run(path: str | Path) -> RunData:
    """Stream the run's bag into arrays."""
    f = mcap_file(path)
    schemas, channels, decoders = {}, {}, {}
    factory = DecoderFactory()
    js, cmd, tru, events = [], [], [], []
    gain = config = None
    counts: dict = {}
    truncated, detail = False, ''
    with open(f, 'rb') as fh:
        reader = StreamReader(fh, skip_magic=False)
        try:
            for rec in reader.records:
                if isinstance(rec, Schema):
                    schemas[rec.id] = rec
                elif isinstance(rec, Channel):
                    channels[rec.id] = rec
                elif isinstance(rec, Metadata):
                    if 'ipfric.config' in rec.metadata:
                        config = json.loads(rec.metadata['ipfric.config'])
                elif isinstance(rec, Message):
                    ch = channels[rec.channel_id]
                    counts[ch.topic] = counts.get(ch.topic, 0) + 1
                    if ch.id not in decoders:
                        decoders[ch.id] = factory.decoder_for(ch.message_encoding, schemas.get(ch.schema_id))
                    topic = ch.topic.lstrip('/')
                    if topic not in ('joint_states', 'voltage_command', 'plant_state', 'safety_event',
                                     'controller_gain'):
                        continue
                    m = decoders[ch.id](rec.data)
                    if topic == 'joint_states':
                        js.append((_stamp(m.header.stamp), m.position[0], m.position[1]))
                    elif topic == 'voltage_command':
                        cmd.append((_stamp(m.measurement_stamp), m.voltage))
                    elif topic == 'plant_state':
                        tru.append((_stamp(m.header.stamp),) + tuple(float(getattr(m, k)) for k in TRUTH_FIELDS))
                    elif topic == 'safety_event':
                        events.append((_stamp(m.header.stamp), m.code, m.detail))
                    else:
                        gain = list(m.data)
        except (McapError, EOFError, ValueError, KeyError, AssertionError, struct.error) as exc:
            truncated, detail = True, f'{type(exc).__name__}: {exc}'
    if not js and not truncated:
        raise ConfigError(f'{f}: no joint_states messages; is this an ipfric run?')
    if not _complete(f):
        truncated = True
        detail = detail or 'no footer: the file was not closed'
    j = np.array(js, float).reshape(-1, 3)
    c = np.array(cmd, float).reshape(-1, 2)
    tr = np.array(tru, float).reshape(-1, 1 + len(TRUTH_FIELDS))
    order = np.argsort(j[:, 0], kind='stable')
    j = j[order]
    return RunData(str(path), j[:, 0], j[:, 1], j[:, 2], c[:, 0], c[:, 1], tr[:, 0],
                   {k: tr[:, i + 1] for i, k in enumerate(TRUTH_FIELDS)}, events, gain, config,
                   counts, truncated, detail)


def _complete(f: Path) -> bool:
    """True if the file ends with the MCAP magic (a closed file)."""
    size = f.stat().st_size
    if size < 8:
        return False
    with open(f, 'rb') as fh:
        fh.seek(size - 8)
        return fh.read(8) == b'\x89MCAP0\r\n'
