"""Clean stop on SIGINT / SIGTERM for the ipfric nodes.

rclpy's own handlers shut the context down at once, after which a node can publish
nothing: the simulator could not announce why the run ended and the recorder could not
take the messages still queued. The nodes therefore initialise rclpy without signal
handlers and install these, which only record the request; every node loop waits with a
short timeout and checks it.
"""
from __future__ import annotations

import signal


class StopRequest:
    """Set by SIGINT or SIGTERM; ``reason`` names the signal."""

    def __init__(self):
        self.reason: str | None = None

    def __bool__(self) -> bool:
        return self.reason is not None

    def request(self, reason: str) -> None:
        if self.reason is None:
            self.reason = reason

    def install(self) -> 'StopRequest':
        def handler(signum, _frame):
            self.request(signal.Signals(signum).name)
        signal.signal(signal.SIGINT, handler)
        signal.signal(signal.SIGTERM, handler)
        return self
