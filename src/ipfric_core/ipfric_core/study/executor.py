"""Where parallel runs execute: a local process pool, or a Dask cluster (``--scheduler ADDRESS``).

:func:`make_executor` is the one place that makes an executor; the sweeps, the resolution
study, the threshold bisection and the Monte Carlo submit their runs to what it returns
(a ``concurrent.futures.Executor``, so ``submit``, ``map`` and ``with`` work alike). A
run's result depends only on its inputs, so the rows are the same wherever it runs.

A cluster's workers import ``ipfric_core`` themselves: start them in this project's
environment (``dask scheduler`` and ``dask worker ADDRESS`` after ``source scripts/env.sh``).
Importing this module loads nothing of Dask; only a scheduler address does.
"""
from __future__ import annotations

import os
import re
import socket
from concurrent.futures import Executor, ProcessPoolExecutor

from ..physics.params import ConfigError

__all__ = ['SCHEDULER_SCHEMES', 'SchedulerError', 'scheduler_address', 'make_executor']

#: seconds to wait for the scheduler before giving up
CONNECT_TIMEOUT_S = 5.0


#: the transports a scheduler address may name (no scheme: tcp)
SCHEDULER_SCHEMES = ('tcp', 'tls')
#: Dask's scheduler port when the address gives none
DEFAULT_PORT = 8786
_ADDRESS = re.compile(r'(?:(?P<scheme>[A-Za-z][A-Za-z0-9+.-]*)://)?'
                      r'(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9](?:[A-Za-z0-9.-]*[A-Za-z0-9])?)'
                      r'(?::(?P<port>[0-9]{1,5}))?/?')


class SchedulerError(ConnectionError):
    """The Dask scheduler of ``--scheduler`` cannot be reached."""


def scheduler_address(address: str) -> tuple[str, int]:
    """(host, port) of ``--scheduler`` ADDRESS, ``[tcp://|tls://]HOST[:PORT]``, checked before any work."""
    m = _ADDRESS.fullmatch(address.strip())
    scheme = (m.group('scheme') or 'tcp').lower() if m else None
    port = int(m.group('port') or DEFAULT_PORT) if m else 0
    if m is None or scheme not in SCHEDULER_SCHEMES or not 1 <= port <= 65535:
        raise ConfigError(f'--scheduler: {address!r} is not a scheduler address; allowed: '
                          f'[{"|".join(s + "://" for s in SCHEDULER_SCHEMES)}]HOST[:PORT] with PORT 1..65535 '
                          f'(default {DEFAULT_PORT}), e.g. tcp://10.0.0.5:8786')
    return m.group('host').strip('[]'), port


#: the largest first message [bytes] a Dask scheduler's handshake may announce
MAX_GREETING = 1 << 20


def _greeting(sock: socket.socket) -> int:
    """The size [bytes] a TCP peer's first message announces, as Dask's framing has it (8 bytes, the
    length of the frames that follow): a scheduler sends its handshake as soon as a client connects.
    0 when the peer closes first; socket.timeout (an OSError) when it says nothing."""
    head = b''
    while len(head) < 8:
        chunk = sock.recv(8 - len(head))
        if not chunk:
            return 0
        head += chunk
    return int.from_bytes(head, 'little')


def make_executor(scheduler: str | None = None, workers: int | None = None,
                  timeout: float = CONNECT_TIMEOUT_S) -> Executor:
    """An executor for independent runs.

    scheduler : None for a local ``ProcessPoolExecutor``, or the address of a running
        ``dask.distributed`` scheduler (e.g. ``tcp://10.0.0.5:8786``).
    workers : local processes (default: all cores); a cluster has its own workers.
    timeout : seconds to wait for the scheduler [s]; past it :class:`SchedulerError`.
    """
    if scheduler is None:
        return ProcessPoolExecutor(max_workers=workers or os.cpu_count())
    host, port = scheduler_address(scheduler)
    try:   # a plain connection first: a Client that never connects takes 10 s more to close
        with socket.create_connection((host, port), timeout=timeout) as sock:
            greeting = _greeting(sock) if not scheduler.strip().lower().startswith('tls://') else None
    except OSError as exc:
        raise SchedulerError(f'--scheduler {scheduler}: no Dask scheduler answers at {host}:{port} within '
                             f'{timeout:g} s ({exc.strerror or type(exc).__name__}); start one with `dask scheduler` '
                             f'and give its address, e.g. tcp://HOST:8786') from None
    if greeting is not None and not 0 < greeting <= MAX_GREETING:
        raise SchedulerError(f'--scheduler {scheduler}: {host}:{port} accepts connections but is no Dask scheduler '
                             f'(its first message is no Dask handshake); start one with `dask scheduler` and give '
                             f'its address, e.g. tcp://HOST:8786')
    from distributed import Client
    try:
        client = Client(scheduler, timeout=timeout, set_as_default=False)
    except Exception as exc:  # refused, timed out, malformed address, not a scheduler at all
        raise SchedulerError(f'--scheduler {scheduler}: no Dask scheduler answers there within {timeout:g} s '
                             f'({type(exc).__name__}: {exc}); start one with `dask scheduler` and give '
                             f'its address, e.g. tcp://HOST:8786') from exc
    return ClusterExecutor(client)


class ClusterExecutor(Executor):
    """A ``concurrent.futures`` executor on a Dask client, which closes the client on shutdown.

    Tasks are submitted as impure (``pure=False``): each submission runs, none is taken from
    another with equal arguments.
    """

    def __init__(self, client):
        self.client = client
        self.executor = client.get_executor(pure=False)

    def submit(self, fn, /, *args, **kwargs):
        return self.executor.submit(fn, *args, **kwargs)

    def map(self, fn, *iterables, timeout=None, chunksize=1):
        return self.executor.map(fn, *iterables, timeout=timeout)

    def shutdown(self, wait=True, *, cancel_futures=False):
        self.executor.shutdown(wait=wait and not cancel_futures)
        self.client.close()
