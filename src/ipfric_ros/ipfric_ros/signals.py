"""Clean stop on SIGINT / SIGTERM / SIGHUP, and on the death of the supervisor, for the nodes.

rclpy's own handlers shut the context down at once, after which a node can publish
nothing: the simulator could not announce why the run ended and the recorder could not
take the messages still queued. The nodes therefore initialise rclpy without signal
handlers and install these, which only record the request; every node loop waits with a
short timeout and checks it.

A node started by ``./ipfric run`` (environment ``IPFRIC_SUPERVISED=1``) also stops when
its supervisor dies, however it dies (``kill -9`` included): the kernel sends it SIGTERM
when its parent exits (``PR_SET_PDEATHSIG``, set here and by the runner before exec), and
a thread watching its stdin (a pipe whose other end only the supervisor holds) sees the
end of file. Either way the node stops as on SIGTERM. The recorder watches its pipe only
and stops ``LINGER_S`` later, so that the simulator's last event is in the bag it closes.
"""
from __future__ import annotations

import os
import signal
import threading
import time
from contextlib import contextmanager
from pathlib import Path

from ipfric_core.run.runner import SUPERVISED, die_with_parent

LINGER_S = 1.0    # [s] the recorder's wait after the supervisor died, for the others' last messages


__all__ = ['FASTDDS_PROFILE', 'LINGER_S', 'StopRequest', 'NodeProcess', 'node_process']


class StopRequest:
    """Set by SIGINT, SIGTERM or SIGHUP; ``reason`` names the first, ``count`` counts the signals."""

    def __init__(self):
        self.reason: str | None = None
        self.count = 0

    def __bool__(self) -> bool:
        return self.reason is not None

    def request(self, reason: str) -> None:
        if self.reason is None:
            self.reason = reason

    def install(self) -> StopRequest:
        def handler(signum, _frame):
            self.count += 1
            self.request(signal.Signals(signum).name)
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
            signal.signal(sig, handler)
        return self

    def watch_supervisor(self, fd: int = 0, linger: float = 0.0) -> threading.Thread:
        """Request a stop ``linger`` s after file descriptor ``fd`` (stdin) reached its end: the
        supervisor is gone.

        (Unbuffered reads: a thread blocked in ``sys.stdin`` would abort the interpreter's exit.)
        """
        def watch():
            while os.read(fd, 4096):
                pass
            time.sleep(linger)
            self.request('the end of the supervisor (its pipe closed)')
        t = threading.Thread(target=watch, name='supervisor-watch', daemon=True)
        t.start()
        return t


class NodeProcess:
    """What a node's ``main`` works with: the stop request, a logger, the nodes to destroy."""

    def __init__(self, name: str):
        import rclpy
        self.stop = StopRequest().install()
        if os.environ.get(SUPERVISED) == '1':
            # the recorder outlives the others by LINGER_S to take their last messages
            linger = LINGER_S if name == 'recorder' else 0.0
            if not linger:
                die_with_parent()
            if os.getppid() == 1:               # the parent died before prctl
                self.stop.request('the end of the supervisor (before start-up)')
            self.stop.watch_supervisor(linger=linger)
        self.logger = rclpy.logging.get_logger(name)
        self.nodes: list = []

    def add(self, node):
        self.nodes.append(node)
        return node


#: The Fast DDS profile of the nodes (fastdds.xml: reliable writers' heartbeat every 20 ms).
FASTDDS_PROFILE = Path(__file__).with_name('fastdds.xml')


@contextmanager
def node_process(name: str, args=None):
    """rclpy initialised without its signal handlers (see above) and with the nodes' Fast DDS
    profile (unless the environment names one); at exit every node added is destroyed and rclpy
    shut down, whatever happened."""
    import rclpy
    from rclpy.signals import SignalHandlerOptions

    from .rclpy_internals import check_version
    check_version()
    if not (os.environ.get('FASTDDS_DEFAULT_PROFILES_FILE') or os.environ.get('FASTRTPS_DEFAULT_PROFILES_FILE')):
        os.environ['FASTDDS_DEFAULT_PROFILES_FILE'] = str(FASTDDS_PROFILE)
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    proc = NodeProcess(name)
    try:
        yield proc
    finally:
        for node in proc.nodes:
            node.destroy_node()
        rclpy.try_shutdown()
