"""Clean stop on SIGINT / SIGTERM for the ipfric nodes.

rclpy's own handlers shut the context down at once, after which a node can publish
nothing: the simulator could not announce why the run ended and the recorder could not
take the messages still queued. The nodes therefore initialise rclpy without signal
handlers and install these, which only record the request; every node loop waits with a
short timeout and checks it.
"""
from __future__ import annotations

import signal
from contextlib import contextmanager


class StopRequest:
    """Set by SIGINT or SIGTERM; ``reason`` names the signal."""

    def __init__(self):
        self.reason: str | None = None

    def __bool__(self) -> bool:
        return self.reason is not None

    def request(self, reason: str) -> None:
        if self.reason is None:
            self.reason = reason

    def install(self) -> StopRequest:
        def handler(signum, _frame):
            self.request(signal.Signals(signum).name)
        signal.signal(signal.SIGINT, handler)
        signal.signal(signal.SIGTERM, handler)
        return self


class NodeProcess:
    """What a node's ``main`` works with: the stop request, a logger, the nodes to destroy."""

    def __init__(self, name: str):
        import rclpy
        self.stop = StopRequest().install()
        self.logger = rclpy.logging.get_logger(name)
        self.nodes: list = []

    def add(self, node):
        self.nodes.append(node)
        return node


@contextmanager
def node_process(name: str, args=None):
    """rclpy initialised without its signal handlers (see above); at exit every node added
    is destroyed and rclpy shut down, whatever happened."""
    import rclpy
    from rclpy.signals import SignalHandlerOptions
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    proc = NodeProcess(name)
    try:
        yield proc
    finally:
        for node in proc.nodes:
            node.destroy_node()
        rclpy.try_shutdown()
