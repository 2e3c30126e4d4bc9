"""The rig's command safety: validation, zero-order hold and watchdog (no ROS imports).

At every sample the plant applies one voltage: the command that arrived for it if it is
valid, else the voltage held from before; a NaN, infinite or out-of-range command is
refused and replaced by 0 V; after ``watchdog_samples`` samples in a row without a valid
command (or ``WATCHDOG_WALL_S`` of wall time, see :meth:`CommandGuard.trip`) the watchdog
trips and holds 0 V until valid commands come back.

Every refused command is counted (:class:`Refusals`): the first of a burst is reported at
once, the rest of the burst once per ``REPORT_EVERY_S`` of wall time and at the end, with
counts per reason, never one event per message.
"""
from __future__ import annotations

import math
from collections import Counter

import numpy as np

BAD_COMMAND = 'BAD_COMMAND'
WATCHDOG = 'WATCHDOG'
WATCHDOG_WALL_S = 2.0     # [s] wall time without a valid command that trips the watchdog (lockstep; a loaded
                          # machine can hold an answer for most of a second)
REPORT_EVERY_S = 1.0      # [s] wall time between two reports of one burst of refused commands


def check_command(voltage, voltage_max: float) -> str | None:
    """None if ``voltage`` [V] may be applied, else the reason it is refused."""
    if isinstance(voltage, bool) or not isinstance(voltage, (int, float)):
        return f'voltage {voltage!r} is not a number'
    if math.isnan(voltage):
        return 'voltage is NaN'
    if math.isinf(voltage):
        return f'voltage is {voltage:+}'
    if abs(voltage) > voltage_max:
        return f'|V| = {abs(voltage):g} V exceeds voltage_max = {voltage_max:g} V'
    return None


def latency_summary(lat: np.ndarray) -> dict:
    """Command latencies [s] as the run's result and the diagnostics report them: count, median, p99, max."""
    if not len(lat):
        return {'commands': 0}
    return {'commands': int(len(lat)), 'median': float(np.median(lat)), 'p99': float(np.percentile(lat, 99)),
            'max': float(lat.max())}


def reason_kind(reason: str) -> str:
    """The counting class of a refusal reason: NaN, inf, out of range, not a number, or itself."""
    for word, kind in (('NaN', 'NaN'), ('inf', 'inf'), ('exceeds', 'out of range'), ('not a number', 'not a number')):
        if word in reason:
            return kind
    return reason


class Refusals:
    """Refused commands, counted per kind; reported per burst (first at once, then summaries)."""

    def __init__(self, every_s: float = REPORT_EVERY_S):
        self.every_s = every_s
        self.total: Counter[str] = Counter()      # kind -> commands refused in the whole run
        self.pending: Counter[str] = Counter()    # kind -> refused since the last report
        self.since: int | None = None             # sample of the first pending refusal
        self.reported_at: float | None = None     # wall time of the last report [s]

    def note(self, kind: str, detail: str, k: int, now: float) -> str | None:
        """Count one refusal at sample ``k``, wall time ``now`` [s]; a report for the first of a burst."""
        self.total[kind] += 1
        if self.reported_at is None or now - self.reported_at >= self.every_s and not self.pending:
            self.reported_at = now
            return f'command refused at sample {k}: {detail}; 0 V applied'
        if not self.pending:
            self.since = k
        self.pending[kind] += 1
        return None

    def report(self, now: float, force: bool = False) -> str | None:
        """The summary of the refusals pending, when due (``force``: at the end of the run)."""
        if not self.pending or not force and self.reported_at is not None and now - self.reported_at < self.every_s:
            return None
        n = sum(self.pending.values())
        detail = (f'{n} more command(s) refused since sample {self.since}: '
                  + ', '.join(f'{c} {kind}' for kind, c in sorted(self.pending.items())))
        self.pending.clear()
        self.reported_at = now
        return detail


class CommandGuard:
    """Voltage applied at each sample from the commands received (ZOH + validation + watchdog).

    Parameters
    ----------
    voltage_max : largest |V| accepted [V]
    watchdog_samples : samples in a row without a valid command before 0 V is forced
    """

    def __init__(self, voltage_max: float, watchdog_samples: int):
        self.voltage_max = float(voltage_max)
        self.watchdog_samples = int(watchdog_samples)
        self.voltage = 0.0      # held voltage [V]
        self.missed = 0         # samples in a row without a valid command
        self.tripped = False
        self.trips = 0          # times the watchdog tripped
        self.refusals = Refusals()
        self.missing = 0        # samples without any command in total

    @property
    def refused(self) -> int:
        return sum(self.refusals.total.values())

    def trip(self, why: str) -> tuple[str, str] | None:
        """Trip the watchdog now (``why``: e.g. no command for a second of wall time); its event."""
        if self.tripped:
            return None
        self.tripped = True
        self.trips += 1
        self.voltage = 0.0
        return WATCHDOG, f'{why}; 0 V applied until commands resume'

    def apply(self, command, k: int = 0, now: float = 0.0) -> tuple[float, list[tuple[str, str]]]:
        """Voltage for sample ``k`` given its ``command`` [V] (None: none arrived), at wall time ``now`` [s].

        Returns (voltage, events) with events as (code, detail) pairs.
        """
        events: list[tuple[str, str]] = []
        if command is None:
            self.missing += 1
            self.missed += 1
        else:
            reason = check_command(command, self.voltage_max)
            if reason is None:
                self.voltage = float(command)
                self.missed = 0
                self.tripped = False
                return self.voltage, events
            self.missed += 1
            self.voltage = 0.0
            first = self.refusals.note(reason_kind(reason), reason, k, now)
            if first:
                events.append((BAD_COMMAND, first))
        if self.missed >= self.watchdog_samples:
            ev = self.trip(f'no valid command for {self.missed} samples')
            if ev:
                events.append(ev)
        if self.tripped:
            self.voltage = 0.0
        return self.voltage, events
