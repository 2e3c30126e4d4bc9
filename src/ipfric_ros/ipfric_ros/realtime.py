"""What keeps a node's sample loop on time: the garbage collector, scheduling, CPU affinity.

Three node-only parameters (:func:`declare_tuning`), applied by :class:`LoopTuning` to the
whole process (every thread, the middleware's included) when the loop starts:

- ``gc_every_samples``: Python's garbage collector is frozen and disabled in the loop and a
  young-generation collection runs after a command is out, every this many samples (0:
  whenever Python decides, which can be in the middle of a sample);
- ``realtime_priority``: SCHED_FIFO at this priority (1..98; 0 = normal scheduling); refused
  without the privilege (CAP_SYS_NICE or an rtprio limit), which is logged, and the loop
  runs on at normal priority. The simulator uses it in realtime only: a lockstep loop runs
  flat out, and at real-time priority it starved its own middleware threads;
- ``cpu``: the CPU the process is bound to (-1 = any); refused CPUs are logged likewise.
"""
from __future__ import annotations

import gc
import os
from dataclasses import dataclass

from .parameters import declare

__all__ = ['Tuning', 'LoopTuning', 'declare_tuning', 'threads']


@dataclass(frozen=True)
class Tuning:
    gc_every_samples: int = 1000
    realtime_priority: int = 0
    cpu: int = -1


def declare_tuning(node, section: str) -> Tuning:
    """Declare the tuning parameters on ``node`` (read-only); their values."""
    d = Tuning()
    return Tuning(
        declare(node, section, 'gc_every_samples', d.gc_every_samples,
                'run the garbage collector only after a command is out, every this many samples '
                '(0 = whenever Python decides)', (0, 10 ** 9), read_only=True),
        declare(node, section, 'realtime_priority', d.realtime_priority,
                'SCHED_FIFO priority of every thread of the process during the loop (0 = normal scheduling)',
                (0, 98), read_only=True),
        declare(node, section, 'cpu', d.cpu, 'the CPU the process is bound to (-1 = any)', (-1, 1023),
                read_only=True))


def threads() -> list[int]:
    """The thread ids of this process."""
    try:
        return [int(t) for t in os.listdir('/proc/self/task')]
    except OSError:
        return [0]


class LoopTuning:
    """The tuning applied for the duration of a loop; :meth:`after_sample` in its slack time,
    :meth:`restore` at its end. ``applied`` says what took effect, for the log and the result."""

    def __init__(self, tuning: Tuning, logger):
        self.tuning = tuning
        self.applied: dict = {'gc_every_samples': tuning.gc_every_samples}
        if tuning.gc_every_samples:
            gc.collect()
            gc.freeze()         # what exists now is never scanned again
            gc.disable()
        if tuning.realtime_priority:
            try:
                for tid in threads():
                    os.sched_setscheduler(tid, os.SCHED_FIFO, os.sched_param(tuning.realtime_priority))
                self.applied['realtime_priority'] = tuning.realtime_priority
            except OSError as exc:
                logger.warning(f'real-time scheduling (SCHED_FIFO {tuning.realtime_priority}) refused: '
                               f'{exc.strerror}; running at normal priority')
                self.applied['realtime_priority'] = 0
        if tuning.cpu >= 0:
            try:
                for tid in threads():
                    os.sched_setaffinity(tid, {tuning.cpu})
                self.applied['cpu'] = tuning.cpu
            except OSError as exc:
                logger.warning(f'binding to CPU {tuning.cpu} refused: {exc.strerror}; running on any CPU')
                self.applied['cpu'] = -1
        logger.info(f'loop tuning: {self.applied}')

    def after_sample(self, k: int) -> None:
        """Slack time after sample ``k``'s work: the young generation's collection when due."""
        every = self.tuning.gc_every_samples
        if every and k % every == 0:
            gc.collect(0 if k % (100 * every) else 2)

    def restore(self) -> None:
        """Normal scheduling and garbage collection again (the node's end runs without a deadline)."""
        if self.tuning.gc_every_samples:
            gc.enable()
            gc.unfreeze()
        if self.applied.get('realtime_priority'):
            for tid in threads():
                try:
                    os.sched_setscheduler(tid, os.SCHED_OTHER, os.sched_param(0))
                except OSError:
                    pass
