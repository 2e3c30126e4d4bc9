"""The rig's command safety: validation, zero-order hold and watchdog (no ROS imports).

At every sample the plant applies one voltage: the command that arrived for it if it is
valid, else the voltage held from before; a NaN, infinite or out-of-range command is
refused and replaced by 0 V; after ``watchdog_samples`` samples in a row without a valid
command the watchdog trips and holds 0 V until valid commands come back.
"""
from __future__ import annotations

import math

BAD_COMMAND = 'BAD_COMMAND'
WATCHDOG = 'WATCHDOG'


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
        self.refused = 0        # commands refused in total
        self.missing = 0        # samples without any command in total

    def apply(self, command) -> tuple[float, list[tuple[str, str]]]:
        """Voltage for this sample given its ``command`` [V] (None: none arrived).

        Returns (voltage, events) with events as (code, detail) pairs.
        """
        events = []
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
            self.refused += 1
            self.missed += 1
            self.voltage = 0.0
            if not self.tripped:
                events.append((BAD_COMMAND, f'{reason}; 0 V applied'))
        if not self.tripped and self.missed >= self.watchdog_samples:
            self.tripped = True
            events.append((WATCHDOG, f'no valid command for {self.missed} samples; 0 V applied '
                                     f'until commands resume'))
        if self.tripped:
            self.voltage = 0.0
        return self.voltage, events
