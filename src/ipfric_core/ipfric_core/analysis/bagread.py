"""Read an ipfric run back from its MCAP file, without a ROS runtime, trusting no byte.

Accepts a rosbag2 directory (metadata.yaml + ``bag_0.mcap``, or ``bag.mcap`` of older runs) or a
bare .mcap file; topics match with or without the leading ``/`` and are counted under their
fully qualified names. A rig recorded in a namespace (``/rig1/joint_states``) is read as one at
the root; a bag with several rigs is read for the one named (``namespace``). The file is
memory-mapped and walked record by record; every length is checked against the end of its
record, chunk and file before it is followed (in the compiled scanner too).

- Chunks: the CRC of the uncompressed records is verified where the writer stored one
  (``zlib.crc32``). A chunk that fails it, or whose header does not hold together, is
  skipped and reported (messages lost, the simulated-time gap); reading resumes at the
  next chunk whose header and CRC validate.
- A file cut short (recorder killed): every complete record is read, also those of an
  incomplete last (uncompressed) chunk, and the file is reported truncated.
- A closed file: its summary (CRC-checked) gives the message counts the reader must find;
  any difference is reported. The run configuration is stored twice (the ``ipfric`` and
  ``rosbag2`` metadata records); copies that differ are reported.
- joint_states and plant_state rows with values that are not finite or not physical
  (bounds in ``ABSURD``) are dropped and reported.
- A file that is not MCAP (no magic: random bytes, empty, a CSV) is refused
  (:class:`ConfigError`, exit code 2 of the commands).
- An intact file can still hold an incomplete run (``RunData.incomplete``): no terminal event
  (the recording stopped before the run ended), or fewer messages than the simulator's last
  event says it published. joint_states stamps that repeat (a second publisher on the rig's
  topics, another run in the domain) are reported as damage.
- ``/parameter_events`` of the rig's nodes give the run-time parameter changes
  (``RunData.parameter_changes``: simulated time, node, parameter, value).

The sample-rate topics (joint_states, voltage_command, plant_state) are taken from their
little-endian CDR by a compiled scanner (about 0.1 us a message instead of 15 us through a
generic decoder); everything else (schemas, channels, the run's metadata, safety events,
the gain, and any message not in little-endian CDR) is decoded with the message
definitions stored in the file itself.
"""
from __future__ import annotations

import json
import mmap
import re
import struct
import zlib
from dataclasses import dataclass, field
from io import BytesIO
from pathlib import Path

import numpy as np
import yaml
from mcap.data_stream import ReadDataStream
from mcap.opcode import Opcode
from mcap.records import Channel, Footer, Message, Metadata, Schema, Statistics
from mcap_ros2.decoder import DecoderFactory

from ..constants import (
    CONTROLLER_GAIN,
    JOINT_STATES,
    PARAMETER_EVENTS,
    PLANT_STATE,
    SAFETY_EVENT,
    TERMINAL_EVENTS,
    VOLTAGE_COMMAND,
)
from ..physics.compiled import compiled
from ..physics.params import ConfigError

__all__ = ['RunData', 'read_run']


@dataclass
class RunData:
    """Arrays of one run (SI units); times are simulated time from header stamps [s].

    ``truncated``: the file ends before its summary (not closed); ``damage``: one sentence
    per damaged part (what, where, messages lost, time span). ``intact`` is False if either.
    """

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
    damage: list = field(default_factory=list)
    namespace: str = '/'
    parameter_changes: list = field(default_factory=list)   # (t, node, name, value)
    recording: dict | None = None                            # how the recorder ended (metadata)
    incomplete: str = ''                                     # why the run in the bag is not whole

    @property
    def intact(self) -> bool:
        return not self.truncated and not self.damage

    @property
    def end_reason(self) -> str | None:
        return self.end_event[0]

    @property
    def end_event(self) -> tuple[str | None, str]:
        """(code, why) of the run's terminal event: why without the counts the simulator appends
        ('stopped by SIGINT', 'duration 20 s reached'); (None, '') without one."""
        for _, code, detail in reversed(self.events):
            if code in TERMINAL_EVENTS:
                return code, detail.split('; samples ')[0]
        return None, ''


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
#: Largest magnitude taken as physical: joint_states (x [m], theta [rad]) and plant_state
#: (x [m], theta [rad], x_dot [m/s], theta_dot [rad/s], friction [N], z [m], stuck, V).
ABSURD = {'joint_states': (1e3, 1e4), 'plant_state': (1e3, 1e4, 1e4, 1e6, 1e6, 1e3, 1.0, 1e6)}

MAGIC = b'\x89MCAP0\r\n'
OP_FOOTER, OP_SCHEMA, OP_CHANNEL, OP_MESSAGE, OP_CHUNK = 2, 3, 4, 5, 6
OP_METADATA, OP_DATA_END, OP_STATISTICS, OP_MAX = Opcode.METADATA, Opcode.DATA_END, Opcode.STATISTICS, 0x0F
RECORDS = {OP_SCHEMA: Schema, OP_CHANNEL: Channel, OP_MESSAGE: Message, OP_METADATA: Metadata}
COMPRESSIONS = ('', 'zstd', 'lz4')
RESYNC = re.compile(rb'[\x06\x0c\x0f]')        # chunk, metadata, data end: where reading may resume
MAX_CHUNK = 1 << 30            # largest uncompressed chunk accepted [bytes]
SKIP, JOINTS, COMMAND, TRUTH, PYTHON = 0, 1, 2, 3, 4
SCANNED = {JOINT_STATES: JOINTS, VOLTAGE_COMMAND: COMMAND, PLANT_STATE: TRUTH}
DECODED = (SAFETY_EVENT, CONTROLLER_GAIN, PARAMETER_EVENTS.lstrip('/'))
# scanner status
END, RECORD, FULL, CUT, BAD = 0, 1, 2, 3, 4


@compiled
def _u32(b, o):
    return np.int64(b[o]) | (np.int64(b[o + 1]) << 8) | (np.int64(b[o + 2]) << 16) | (np.int64(b[o + 3]) << 24)


@compiled
def _f64(b, o, tmp):
    for i in range(8):
        tmp[i] = b[o + i]
    return tmp.view(np.float64)[0]


@compiled
def _align(p, n):
    return (p + n - 1) // n * n


@compiled
def _scan(b, pos, kinds, counts, js, cmd, tru, n):
    """Scan the records of a chunk from ``pos``: count every message per channel and take the
    fields of joint_states, voltage_command and plant_state (little-endian CDR) into ``js``
    (t, x, theta), ``cmd`` (measurement t, V) and ``tru`` (t, TRUTH_FIELDS), ``n`` their
    fill levels. Every offset is checked against the end of its record before it is read.
    Stops at a record Python must handle (status RECORD), when an output is full (FULL), at
    the end (END), at a record cut short (CUT) or at a message whose CDR does not fit in its
    record (BAD); returns (pos, status).
    """
    tmp = np.empty(8, np.uint8)
    size = len(b)
    while pos < size:
        if pos + 9 > size:
            return pos, CUT
        op = b[pos]
        hi = _u32(b, pos + 5)
        if hi != 0:                                   # a length of 4 GiB or more: not in a chunk
            return pos, CUT
        end = pos + 9 + _u32(b, pos + 1)
        if end > size:
            return pos, CUT
        if op != OP_MESSAGE:
            return pos, RECORD
        c = pos + 9
        if c + 26 > end:                              # channel, sequence, times, CDR header
            return pos, BAD
        ch = np.int64(b[c]) | (np.int64(b[c + 1]) << 8)
        kind = kinds[ch]
        if kind == PYTHON or (kind != SKIP and b[c + 23] != 1):  # not little-endian CDR
            return pos, RECORD
        if kind != SKIP:
            out = js if kind == JOINTS else cmd if kind == COMMAND else tru
            if n[kind - 1] == len(out):
                return pos, FULL
            d = c + 26                               # CDR body, after the 4-byte encapsulation
            m = end - d                              # CDR body length
            if m < 12:
                return pos, BAD
            t = np.int32(_u32(b, d)) + 1e-9 * _u32(b, d + 4)
            p = 12 + _u32(b, d + 8)                  # after header.frame_id
            if p > m:
                return pos, BAD
            row = n[kind - 1]
            if kind == JOINTS:
                p = _align(p, 4)
                if p + 4 > m:
                    return pos, BAD
                names = _u32(b, d + p)
                p += 4
                for _ in range(names):               # joint names: each advances p by 4 or more
                    p = _align(p, 4)
                    if p + 4 > m:
                        return pos, BAD
                    p += 4 + _u32(b, d + p)
                    if p > m:
                        return pos, BAD
                p = _align(p, 4)
                if p + 4 > m:
                    return pos, BAD
                count = _u32(b, d + p)
                p = _align(p + 4, 8)
                if p + 8 * min(count, 2) > m:
                    return pos, BAD
                js[row, 0] = t
                js[row, 1] = _f64(b, d + p, tmp) if count > 0 else np.nan
                js[row, 2] = _f64(b, d + p + 8, tmp) if count > 1 else np.nan
            elif kind == COMMAND:
                p = _align(p, 8)
                if p + 16 > m:
                    return pos, BAD
                v = _f64(b, d + p, tmp)
                p += 8
                cmd[row, 0] = np.int32(_u32(b, d + p)) + 1e-9 * _u32(b, d + p + 4)
                cmd[row, 1] = v
            else:
                p = _align(p, 8)
                q = _align(p + 49, 8)
                if q + 8 > m:
                    return pos, BAD
                tru[row, 0] = t
                for i in range(6):
                    tru[row, 1 + i] = _f64(b, d + p + 8 * i, tmp)
                tru[row, 7] = 1.0 if b[d + p + 48] else 0.0
                tru[row, 8] = _f64(b, d + q, tmp)
            n[kind - 1] += 1
        counts[ch] += 1
        pos = end
    return pos, END


@compiled
def _count_messages(b):
    """Message records in a chunk's record area, following lengths only within it."""
    pos, size, k = 0, len(b), 0
    while pos + 9 <= size:
        if _u32(b, pos + 5) != 0:
            break
        end = pos + 9 + _u32(b, pos + 1)
        if end > size:
            break
        if b[pos] == OP_MESSAGE:
            k += 1
        pos = end
    return k


class _Reader:
    """Walks one memory-mapped MCAP file; ``damage`` collects what could not be read."""

    def __init__(self, keep, buf, namespace: str | None = None):
        self.keep = keep
        self.buf = buf
        self.namespace = namespace      # the rig read (None: the first whose joint_states appear)
        self.rigs: set[str] = set()     # namespaces with joint_states in the bag
        self.parameter_events: list = []
        self.schemas: dict = {}
        self.channels: dict = {}
        self.decoders: dict = {}
        self.factory = DecoderFactory()
        self.kinds = np.zeros(65536, np.int8)
        self.counts = np.zeros(65536, np.int64)
        self.n = np.zeros(3, np.int64)
        self.out = [np.empty((4096, 3)), np.empty((4096, 2)), np.empty((4096, 1 + len(TRUTH_FIELDS)))]
        self.events: list = []
        self.gain: list | None = None
        self.metadata: dict = {}
        self.damage: list = []      # (sentence, joint_states index where samples are missing or None)
        self.bad_messages = 0       # messages that did not decode or fit in their record

    # ------------------------------------------------------------------ records
    def record(self, op: int, content: bytes) -> None:
        """A record the scanner leaves to Python: schema, channel, metadata, other messages."""
        if op not in RECORDS:
            return
        stream = ReadDataStream(BytesIO(content))
        rec = Message.read(stream, len(content)) if op == OP_MESSAGE else RECORDS[op].read(stream)  # type: ignore[attr-defined]
        if isinstance(rec, Schema):
            self.schemas[rec.id] = rec
        elif isinstance(rec, Channel):
            self.channel(rec)
        elif isinstance(rec, Metadata):
            self.metadata[rec.name] = rec.metadata
        elif isinstance(rec, Message):
            self.message(rec)

    def channel(self, rec: Channel) -> None:
        self.channels[rec.id] = rec
        namespace, topic = _split(rec.topic)
        if topic == JOINT_STATES:
            self.rigs.add(namespace)
            if self.namespace is None:
                self.namespace = namespace
        kind = SCANNED.get(topic, PYTHON if topic in DECODED else SKIP)
        mine = namespace == self.namespace or topic == PARAMETER_EVENTS.lstrip('/')
        self.kinds[rec.id] = kind if mine and kind != SKIP and (topic in self.keep or kind == PYTHON) else SKIP

    def message(self, rec: Message) -> None:
        ch = self.channels.get(rec.channel_id)
        if ch is None:
            self.bad_messages += 1
            return
        self.counts[ch.id] += 1
        if ch.id not in self.decoders:
            self.decoders[ch.id] = self.factory.decoder_for(ch.message_encoding, self.schemas.get(ch.schema_id))
        namespace, topic = _split(ch.topic)
        if namespace != self.namespace and topic != PARAMETER_EVENTS.lstrip('/'):
            return
        m = self.decoders[ch.id](rec.data)
        row: tuple | None = None
        if topic == JOINT_STATES:
            row, kind = (_stamp(m.header.stamp), m.position[0], m.position[1]), JOINTS
        elif topic == VOLTAGE_COMMAND:
            row, kind = (_stamp(m.measurement_stamp), m.voltage), COMMAND
        elif topic == PLANT_STATE:
            row, kind = (_stamp(m.header.stamp),) + tuple(float(getattr(m, k)) for k in TRUTH_FIELDS), TRUTH
        elif topic == SAFETY_EVENT:
            self.events.append((_stamp(m.header.stamp), m.code, m.detail))
        elif topic == CONTROLLER_GAIN:
            self.gain = list(m.data)
        elif topic == PARAMETER_EVENTS.lstrip('/'):
            for changed, params in ((False, m.new_parameters), (True, m.changed_parameters)):
                self.parameter_events += [(_stamp(m.stamp), m.node, p.name, _parameter_value(p.value), changed)
                                          for p in params]
        if row is not None and topic in self.keep:
            self._grow(kind - 1)
            self.out[kind - 1][self.n[kind - 1]] = row
            self.n[kind - 1] += 1

    def _grow(self, i: int) -> None:
        if self.n[i] == len(self.out[i]):
            self.out[i] = np.concatenate([self.out[i], np.empty_like(self.out[i])])

    def records(self, buf) -> int:
        """Every record of a chunk's record area; returns where it stops (len(buf) if complete)."""
        b = np.frombuffer(buf, np.uint8)
        pos = 0
        while True:
            pos, status = _scan(b, pos, self.kinds, self.counts, *self.out, self.n)
            if status in (END, CUT):
                return pos
            if status == FULL:
                for i in range(3):
                    self._grow(i)
                continue
            end = pos + 9 + int.from_bytes(buf[pos + 1:pos + 9], 'little')
            if status == BAD:
                self.bad_messages += 1
            else:
                try:
                    self.record(buf[pos], bytes(buf[pos + 9:end]))
                except Exception:                       # noqa: BLE001 - any malformed record
                    self.bad_messages += 1
            pos = end

    # ------------------------------------------------------------------ chunks
    def chunk(self, pos: int):
        """Parse the chunk record at ``pos`` from its own fields, bounded by the file.

        Returns (end, records, verified, problem): ``records`` the uncompressed record area
        (None if unusable), ``problem`` '' or why the chunk is not trusted.
        """
        b, size = self.buf, len(self.buf)
        h = pos + 9
        if h + 32 > size:
            return size, None, False, 'chunk header cut short'
        _, _, usize, crc, clen = struct.unpack_from('<QQQII', b, h)
        if clen > 8 or h + 32 + clen + 8 > size:
            return size, None, False, 'chunk header cut short' if clen <= 8 else 'chunk header damaged'
        compression = bytes(b[h + 32:h + 32 + clen]).decode('latin-1')
        rlen = struct.unpack_from('<Q', b, h + 32 + clen)[0]
        start = h + 32 + clen + 8
        end = start + rlen
        if compression not in COMPRESSIONS or usize > MAX_CHUNK or (compression == '' and usize != rlen):
            return end, None, False, 'chunk header damaged'
        if end > size:                                   # cut short: the complete records of it
            if compression:
                return size, None, False, 'compressed chunk cut short'
            return size, memoryview(b)[start:size], False, 'cut short'
        data: bytes | memoryview = memoryview(b)[start:end]
        try:
            if compression == 'zstd':
                import zstandard
                data = zstandard.decompress(bytes(data), max_output_size=usize)
            elif compression == 'lz4':
                import lz4.frame
                data = lz4.frame.decompress(bytes(data))
        except Exception:                                # noqa: BLE001 - corrupt compressed data
            return end, None, False, 'chunk does not decompress'
        if len(data) != usize:
            return end, None, False, 'chunk size does not match its header'
        if crc and zlib.crc32(data) != crc:
            return end, data, False, 'chunk CRC mismatch'
        return end, data, bool(crc), ''

    def resync(self, pos: int) -> int | None:
        """The next offset after ``pos`` where a record starts that validates: a chunk (header
        and CRC), a metadata record followed by a record, or the data end record."""
        b, size = self.buf, len(self.buf)
        for m in RESYNC.finditer(b, pos + 1):
            p = m.start()
            if p + 9 > size:
                return None
            op, length = b[p], int.from_bytes(b[p + 1:p + 9], 'little')
            if op == OP_CHUNK:
                _, data, verified, problem = self.chunk(p)
                if data is not None and (verified or problem == 'cut short'):
                    return p
            elif op == OP_DATA_END:
                if length == 4:
                    return p
            elif p + 10 + length <= size and 0 < b[p + 9 + length] <= OP_MAX:
                try:
                    Metadata.read(ReadDataStream(BytesIO(bytes(b[p + 9:p + 9 + length]))))
                except Exception:                       # noqa: BLE001 - not a metadata record
                    continue
                return p
        return None

    # ------------------------------------------------------------------ the file
    def read(self) -> str:
        """Read the file; '' or why it ends early (truncated)."""
        b, size = self.buf, len(self.buf)
        pos = 8
        while True:
            if pos + 9 > size:
                return 'the file ends inside a record header' if pos < size else 'no footer: the file was not closed'
            op = b[pos]
            length = int.from_bytes(b[pos + 1:pos + 9], 'little')
            end = pos + 9 + length
            if op == OP_CHUNK:
                nxt = self.read_chunk(pos)
                if nxt is None:
                    return 'the last chunk is cut short'
                pos = nxt
                if pos >= size:
                    return 'no footer: the file was not closed'
                continue
            if op == 0 or op > OP_MAX or end > size:
                nxt = self.resync(pos)
                if nxt is None:
                    if op == 0 or op > OP_MAX:
                        self.damage.append((f'damaged bytes from offset {pos} to the end of the file '
                                            f'(no readable record)', None))
                        return ''
                    return f'a record (opcode {op:#x}) is cut short at offset {pos}'
                self.damage.append((f'damaged record at offset {pos}: skipped {nxt - pos} bytes up to the '
                                    f'next valid chunk', int(self.n[0])))
                pos = nxt
                continue
            if op in (OP_DATA_END, OP_FOOTER):
                return ''
            if op in RECORDS:
                try:
                    self.record(op, bytes(b[pos + 9:end]))
                except Exception:                       # noqa: BLE001 - any malformed record
                    self.damage.append((f'damaged record (opcode {op:#x}) at offset {pos}', None))
            pos = end

    def read_chunk(self, pos: int) -> int | None:
        """Read the chunk at ``pos``; returns the offset after it (None: cut short)."""
        end, data, verified, problem = self.chunk(pos)
        if problem == 'cut short':
            self.records(data)
            return None
        if problem.endswith('cut short'):
            return None
        if problem:
            lost = _count_messages(np.frombuffer(data, np.uint8)) if data is not None else None
            nxt = end if data is not None else self.resync(pos)   # a CRC mismatch: the header holds
            what = f'{lost} messages lost' if lost is not None else 'its messages lost'
            self.damage.append((f'chunk at offset {pos} skipped ({problem}): {what}', int(self.n[0])))
            return nxt if nxt is not None else len(self.buf)
        stop = self.records(data)
        if stop < len(data):
            self.damage.append((f'chunk at offset {pos}: records after byte {stop} of {len(data)} unreadable',
                                int(self.n[0])))
        return end

    # ------------------------------------------------------------------ the summary
    def summary(self) -> dict | None:
        """Message counts per channel id from the summary of a closed file (CRC-checked), or None;
        its schemas and channels are taken too (so that a skipped first chunk loses no channel)."""
        b, size = self.buf, len(self.buf)
        f = size - 8 - 29
        if f < 8 or bytes(b[size - 8:]) != MAGIC or b[f] != OP_FOOTER:
            return None
        footer = Footer.read(ReadDataStream(BytesIO(bytes(b[f + 9:f + 29]))))
        start = footer.summary_start
        if not 8 <= start <= f:
            return None
        if footer.summary_crc and zlib.crc32(b[start:f + 25]) != footer.summary_crc:
            self.damage.append(('the summary section fails its CRC (message counts not checked)', None))
            return None
        pos, counts = start, None
        while pos + 9 <= f:
            op, length = b[pos], int.from_bytes(b[pos + 1:pos + 9], 'little')
            if pos + 9 + length > f:
                break
            content = bytes(b[pos + 9:pos + 9 + length])
            if op == OP_STATISTICS:
                counts = Statistics.read(ReadDataStream(BytesIO(content))).channel_message_counts
            elif op in (OP_SCHEMA, OP_CHANNEL):
                self.record(op, content)
            pos += 9 + length
        return counts


def _split(topic: str) -> tuple[str, str]:
    """('/rig1', 'joint_states') of '/rig1/joint_states'; ('/', 'joint_states') of '/joint_states' or 'joint_states'."""
    namespace, _, name = ('/' + topic.lstrip('/')).rpartition('/')
    return namespace or '/', name


def _parameter_value(v):
    """The value of an rcl_interfaces/ParameterValue (decoded from the bag) as plain Python."""
    field_of = {1: 'bool_value', 2: 'integer_value', 3: 'double_value', 4: 'string_value', 5: 'byte_array_value',
                6: 'bool_array_value', 7: 'integer_array_value', 8: 'double_array_value', 9: 'string_array_value'}
    name = field_of.get(v.type)
    if name is None:
        return None
    value = getattr(v, name)
    return list(value) if v.type >= 5 else value


def read_run(path: str | Path, keep=tuple(SCANNED), namespace: str | None = None) -> RunData:
    """Stream the run's bag into arrays.

    ``keep``: the sample-rate topics whose arrays to fill (joint_states, voltage_command,
    plant_state); the others are only counted (not decoded, so not checked) and their arrays
    left empty. ``namespace``: the rig to read in a bag of several (None: the bag's only one).
    Raises :class:`ConfigError` for a file that is not MCAP or holds no ipfric run.
    """
    f = mcap_file(path)
    size = f.stat().st_size
    with open(f, 'rb') as fh:
        head = fh.read(8)
        if head != MAGIC:
            what = 'it is empty' if not head else f'it starts with {head[:8]!r}'
            raise ConfigError(f'{f}: not an MCAP file ({what}; an MCAP file starts with {MAGIC!r}); give the '
                              f'bag directory or .mcap file of a run (./ipfric run --out DIR writes DIR/bag)')
        mm = mmap.mmap(fh.fileno(), size, access=mmap.ACCESS_READ)   # closed when unreferenced
    ns = None if namespace is None else '/' + namespace.strip('/')
    r = _Reader(set(keep) | {'joint_states'}, mm, ns.rstrip('/') or '/' if ns else None)
    expected = r.summary()
    detail = r.read()
    if ns is None and len(r.rigs) > 1:
        raise ConfigError(f'{f}: the bag holds the joint_states of several rigs ({", ".join(sorted(r.rigs))}); '
                          f'name the one to read (analyze --namespace NS)')
    if expected is not None:
        short = [f'{r.channels[c].topic if c in r.channels else c} {int(r.counts[c])} of {k}'
                 for c, k in sorted(expected.items()) if int(r.counts[c]) != k]
        if short:
            r.damage.append(('messages read of those the summary lists: ' + ', '.join(short), None))
    elif not detail and mm[size - 8:] != MAGIC:
        detail = 'no footer: the summary is cut short (every data record was read)'
    truncated = bool(detail)
    if r.bad_messages:
        r.damage.append((f'{r.bad_messages} message(s) did not decode or did not fit in their record', None))
    config = _config(r)
    counts = {'/' + r.channels[c].topic.lstrip('/'): int(r.counts[c]) for c in sorted(r.channels)}
    j, c, tr = (o[:k] for o, k in zip(r.out, r.n))
    damage = [_located(s, k, j[:, 0]) for s, k in r.damage]
    j, tr = _physical(j, 'joint_states', damage), _physical(tr, 'plant_state', damage)
    if not len(j) and not truncated and not damage:
        where = f' of namespace {r.namespace}' if ns else ''
        raise ConfigError(f'{f}: no joint_states messages{where}; is this an ipfric run?')
    order = np.argsort(j[:, 0], kind='stable')
    j = j[order]
    repeated = int(np.count_nonzero(np.diff(j[:, 0]) <= 0))
    if repeated:
        damage.append(f'joint_states: {repeated} sample(s) whose stamp another message has too: a second publisher '
                      f'on the rig\'s topics (another rig or run in the domain); the samples are not one run\'s')
    rig = r.namespace or '/'
    changes = [(t, node, name, value) for t, node, name, value, changed in r.parameter_events
               if changed and _split(node)[0] == rig]
    recording = _metadata_json(r, 'ipfric.recording')
    run = RunData(str(path), j[:, 0], j[:, 1], j[:, 2], c[:, 0], c[:, 1], tr[:, 0],
                  {k: tr[:, i + 1] for i, k in enumerate(TRUTH_FIELDS)}, r.events, r.gain, config,
                  counts, truncated, detail, damage, rig, changes, recording)
    run.incomplete = _incomplete(run)
    return run


def _incomplete(run: RunData) -> str:
    """Why the bag does not hold the whole run ('' if it does): no terminal event, or fewer
    messages than the simulator's terminal event says it published."""
    ends = [d for _, code, d in run.events if code in TERMINAL_EVENTS]
    if not ends:
        stopped = (run.recording or {}).get('stopped_by')
        return ('the run\'s end is not in the bag (no END, ABORT, FALLEN or TRACK_LIMIT event): the recording stopped '
                'before the run ended' + (f' (the recorder was stopped by {stopped})' if stopped else ''))
    try:
        published = json.loads(ends[-1].split('published ', 1)[1])
    except (IndexError, ValueError):
        return ''
    prefix = '' if run.namespace == '/' else run.namespace
    short = []
    for topic, n in published.items():
        name = topic if topic.startswith('/') else f'{prefix}/{topic}'
        if run.counts.get(name, 0) < n:
            short.append(f'{name} {run.counts.get(name, 0)} of {n}')
    return ('the bag holds fewer messages than the simulator published: ' + ', '.join(short)) if short else ''


def _metadata_json(r: _Reader, key: str) -> dict | None:
    """A JSON entry of the ``ipfric`` metadata record (None if absent or not JSON)."""
    try:
        return json.loads(r.metadata.get('ipfric', {})[key])
    except (KeyError, ValueError):
        return None


def _located(sentence: str, before: int | None, t: np.ndarray) -> str:
    """``sentence`` with the simulated-time gap in joint_states where the loss happened."""
    if before is None or not len(t):
        return sentence
    lo = f't = {t[before - 1]:.3f} s' if before > 0 else 'the start'
    hi = f't = {t[before]:.3f} s' if before < len(t) else 'the end'
    return f'{sentence}; samples missing between {lo} and {hi} (simulated time)'


def _physical(rows: np.ndarray, topic: str, damage: list) -> np.ndarray:
    """``rows`` without those holding a non-finite or absurd value (reported in ``damage``)."""
    if not len(rows):
        return rows
    values = rows[:, 1:]
    limit = np.array(ABSURD[topic][:values.shape[1]])
    ok = np.isfinite(rows[:, 0]) & (np.isfinite(values) & (np.abs(values) <= limit)
                                    | np.isnan(values) & (topic == 'joint_states')).all(axis=1)
    if ok.all():
        return rows
    bad = np.flatnonzero(~ok)
    names = ('x', 'theta') if topic == 'joint_states' else TRUTH_FIELDS
    bounds = ', '.join(f'|{k}| {v:g}' for k, v in zip(names, limit))
    damage.append(f'{topic}: {len(bad)} message(s) with a value not finite or beyond {bounds} dropped, '
                  f'the first at t = {rows[bad[0], 0]:.3f} s')
    return rows[ok]


def _config(r: _Reader) -> dict | None:
    """The run configuration from the ``ipfric`` metadata record, checked against the copy in ``rosbag2``."""
    text = r.metadata.get('ipfric', {}).get('ipfric.config')
    if text is None:
        return None
    try:
        config = json.loads(text)
    except ValueError:
        r.damage.append(('the run configuration (metadata record ipfric) is not valid JSON; not used', None))
        return None
    copy = r.metadata.get('rosbag2', {}).get('serialized_metadata')
    if copy is not None:
        try:
            custom = yaml.safe_load(copy)['custom_data']['ipfric.config']
        except Exception:                                # noqa: BLE001 - a damaged copy
            custom = None
        if custom != text:
            r.damage.append(('the run configuration differs between the metadata records ipfric and rosbag2; '
                             'not used', None))
            return None
    return config
