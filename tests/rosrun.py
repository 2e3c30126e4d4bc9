"""Helpers of the ROS tests: scenario files, node processes and an in-process peer.

Every process and the in-process rclpy context get a ROS_DOMAIN_ID of their own (a free
one, held: :func:`ipfric_core.run.runner.claim_domain`) and ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST.
"""
from __future__ import annotations

import os
import subprocess
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import yaml

from ipfric_core.run.runner import Run, claim_domain, executable, ros_environment
from ipfric_core.run.scenario import SECTION_KEYS

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / 'config'


def scenario_file(tmp_path: Path, name: str, sim: dict | None = None, controller: dict | None = None,
                  out: str = 'scenario.yaml') -> Path:
    """config/<name>.yaml with entries of the two sections replaced (dotted keys nest)."""
    data = yaml.safe_load((CONFIG / name).read_text())
    for section, changes in (('sim_node', sim), ('controller_node', controller)):
        params = data[SECTION_KEYS[section]]['ros__parameters']
        for key, value in (changes or {}).items():
            node = params
            *path, leaf = key.split('.')
            for p in path:
                node = node[p]
            node[leaf] = value
    path = tmp_path / out
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def start_node(name: str, args: list, domain: int, log: Path) -> subprocess.Popen:
    """One ipfric node executable in ``domain`` (loopback only), output to ``log``."""
    env = ros_environment(domain)
    env['ROS_LOG_DIR'] = str(log.parent / 'ros')
    return subprocess.Popen([str(executable(name)), '--ros-args', *args], env=env, cwd=log.parent,
                            stdout=open(log, 'w'), stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)


def p2p(t: np.ndarray, x: np.ndarray, last: float = 5.0) -> float:
    """Peak-to-peak of ``x`` over the last ``last`` seconds of ``t``."""
    w = t >= t[-1] - last
    return float(x[w].max() - x[w].min())


class Peer:
    """An rclpy context and node in the test process, in its own domain on loopback."""

    def __init__(self, name: str, domain: int | None = None):
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        assert os.environ.get('ROS_AUTOMATIC_DISCOVERY_RANGE') == 'LOCALHOST', \
            'run the tests through ./ipfric test (scripts/env.sh keeps DDS on loopback)'
        self.lock = claim_domain() if domain is None else None     # held: runs started beside it pick others
        self.domain = domain if self.lock is None else self.lock.domain
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=self.domain)
        self.node = rclpy.create_node(name, context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)

    def spin_until(self, condition, timeout: float, what: str) -> None:
        t0 = time.monotonic()
        while not condition():
            assert time.monotonic() - t0 < timeout, f'timed out after {timeout:g} s waiting for {what}'
            self.executor.spin_once(timeout_sec=0.02)

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()
        self.context.try_shutdown()
        if self.lock is not None:
            self.lock.release()


def started(log: Path, proc, timeout: float = 120.0) -> None:
    """Until the simulator logged sample 0 (a hang guard, not a timing)."""
    t0 = time.monotonic()
    while not (log.exists() and 'START at sample 0' in log.read_text()):
        assert proc.poll() is None, f'{proc.args[0]} exited: ' + (log.read_text()[-2000:] if log.exists() else '')
        assert time.monotonic() - t0 < timeout, 'the run did not start'
        time.sleep(0.05)


@contextmanager
def run_beside_peer(config, out: Path, name: str, setup=None, **kwargs):
    """A :class:`Run` of ``config`` and, before its nodes start (so that the peer is discovered by
    sample 0), a :class:`Peer` ``name`` in the run's domain, given to ``setup`` (its publishers,
    subscriptions and clients) then; both ended however the block ends. Yields (run, peer, what
    ``setup`` returned)."""
    r = Run(config, out, timeout=300, **kwargs)
    peer = None
    try:
        r.prepare()
        peer = Peer(name, domain=r.domain)
        ready = setup(peer) if setup else None
        r.start()
        started(r.logs['sim_node'], r.procs['sim_node'])
        yield r, peer, ready
    finally:
        if peer is not None:
            peer.close()
        r.kill()
