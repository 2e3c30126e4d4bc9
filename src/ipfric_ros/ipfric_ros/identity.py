"""Messages taken by their publisher's identity: the node of the rig that should send them.

A rig's controller obeys the joint states of its simulator (or rig driver) only, and the
simulator the commands of its controller only. Each message carries its publisher's GID
(:func:`ipfric_ros.rclpy_internals.publisher_gid`); the ROS graph tells which node owns that
publisher. :class:`Publishers` keeps the verdict per GID: the expected node's publishers are
accepted (also a restarted one), every other publisher is a stranger, counted per node and
never obeyed. A stranger's messages cost a dictionary look-up each, so a flood cannot hold
the loop. Without DDS security (not in the PyPI wheels) this is what keeps a rig its own.
"""
from __future__ import annotations

import time
from collections import Counter

__all__ = ['UNKNOWN', 'Publishers', 'node_of']

#: [s] shortest interval between two graph look-ups for a GID the graph does not know yet
LOOKUP_EVERY_S = 0.01
#: What the graph says of a publisher whose node it does not know yet (rmw's placeholder name).
UNKNOWN = '_NODE_NAME_UNKNOWN_'


def node_of(info) -> str:
    """The fully qualified node name of a TopicEndpointInfo; '?' while the graph does not know it."""
    if UNKNOWN in info.node_name:
        return '?'
    return f'{info.node_namespace.rstrip("/")}/{info.node_name}'


class Publishers:
    """The publishers of ``topic`` as seen by ``node``: those of node ``expected`` (a name in the
    node's namespace, or a fully qualified name) and the strangers."""

    def __init__(self, node, topic: str, expected: str):
        self.node = node
        self.topic = node.resolve_topic_name(topic)
        ns = node.get_namespace().rstrip('/')
        self.expected = expected if expected.startswith('/') else f'{ns}/{expected}'
        self.accepted: set[bytes] = set()
        self.strangers: dict[bytes, str] = {}    # GID -> fully qualified node name ('?' if unknown)
        self.refused: Counter[str] = Counter()   # node -> messages refused
        self._looked = 0.0

    def lookup(self) -> None:
        """Sort the publishers the graph shows now into accepted and strangers."""
        self._looked = time.monotonic()
        for info in self.node.get_publishers_info_by_topic(self.topic):
            gid = bytes(info.endpoint_gid)
            fqn = node_of(info)
            if fqn == self.expected:
                self.accepted.add(gid)
                self.strangers.pop(gid, None)
            elif gid not in self.accepted:
                self.strangers[gid] = fqn

    def present(self) -> list[bytes]:
        """The expected node's publishers in the graph now (after a look-up)."""
        self.lookup()
        live = {bytes(i.endpoint_gid) for i in self.node.get_publishers_info_by_topic(self.topic)}
        return [g for g in self.accepted if g in live]

    def accepts(self, gid: bytes) -> bool:
        """Whether a message from publisher ``gid`` is to be obeyed; a refusal is counted."""
        if gid in self.accepted:
            return True
        if gid not in self.strangers or self.strangers[gid] == '?':
            if time.monotonic() - self._looked >= LOOKUP_EVERY_S:
                self.lookup()
            if gid in self.accepted:
                return True
            self.strangers.setdefault(gid, '?')
        self.refused[self.strangers[gid]] += 1
        return False

    def stranger_nodes(self) -> list[str]:
        """The strangers' nodes, by name ('?' for a publisher the graph did not name)."""
        return sorted(set(self.strangers.values()))
