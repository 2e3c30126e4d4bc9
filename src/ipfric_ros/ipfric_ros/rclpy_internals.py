"""The rclpy internals the ipfric nodes use, in one place, checked against the rclpy version.

rclpy has no public API for three things the nodes need:

- the publisher GID of a message (``message_info['publisher_gid']``), to refuse commands
  from a second writer on a topic;
- a wait set on a single subscription (``_rclpy.WaitSet``, as ``rclpy.wait_for_message``
  uses it) and taking its messages with their info (``handle.take_message``): the
  lockstep simulator and the recorder wait on their data subscriptions alone, cheaper
  than an executor turn over every entity of the node;
- the parameter-file entries before declaration (``node._parameter_overrides``): to
  accept ``duration: 5`` where a double is declared and to name unknown parameters.

These were written against rclpy 9.1 (ROS 2 Kilted); :func:`check_version` refuses
another minor version at start-up with a sentence instead of failing mid-run.
"""
from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

__all__ = ['RCLPY_SERIES', 'rclpy_version', 'check_version', 'SubscriptionWaiter', 'publisher_gid',
           'parameter_overrides']

#: The rclpy release line the internals below were checked with (major, minor).
RCLPY_SERIES = (9, 1)


def rclpy_version() -> str:
    """The installed rclpy version: the PyPI wheel's, or a colcon/apt install's; '?' if unknown."""
    for dist in ('ros-rclpy', 'rclpy'):
        try:
            return version(dist)
        except PackageNotFoundError:
            continue
    return '?'


def check_version(found: str | None = None) -> None:
    """RuntimeError unless rclpy is of the RCLPY_SERIES line (``found``: a version string)."""
    found = found or rclpy_version()
    parts = found.split('.')[:2]
    if not all(p.isdigit() for p in parts) or tuple(int(p) for p in parts) != RCLPY_SERIES:
        raise RuntimeError(f'rclpy {found}: ipfric_ros.rclpy_internals was checked with rclpy '
                           f'{RCLPY_SERIES[0]}.{RCLPY_SERIES[1]}.x only (WaitSet, take_message, '
                           f'_parameter_overrides); check them against this version and update RCLPY_SERIES')


class SubscriptionWaiter:
    """Wait on some subscriptions (and services) alone and take what the subscriptions hold (with
    the publisher's GID); the services are left to an executor turn when :meth:`wait` says one
    has a request."""

    def __init__(self, node, *subscriptions, services=()):
        from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
        self.subscriptions = subscriptions
        self.services = tuple(services)
        self.wait_set = _rclpy.WaitSet(len(subscriptions), 0, 0, 0, len(self.services), 0, node.context.handle)

    def wait(self, timeout_s: float) -> bool:
        """Return when a message or a request is there or after ``timeout_s`` [s]; whether a
        service has a request."""
        ws = self.wait_set
        ws.clear_entities()
        for sub in self.subscriptions:
            ws.add_subscription(sub.handle)
        for srv in self.services:
            ws.add_service(srv.handle)
        ws.wait(int(timeout_s * 1e9))
        return bool(self.services) and bool(ws.get_ready_entities('service'))

    def take(self, i: int = 0):
        """(message, publisher GID as bytes) from subscription ``i``, or None when nothing is queued
        (the message serialized if the subscription is raw)."""
        sub = self.subscriptions[i]
        got = sub.handle.take_message(sub.msg_type, sub.raw)
        if got is None:
            return None
        return got[0], publisher_gid(got[1])


def publisher_gid(info) -> bytes:
    """The publisher GID in a message info (``take_message``'s, or the second argument rclpy
    passes to a subscription callback that takes two); b'' if absent."""
    return bytes(info.get('publisher_gid', {}).get('data', b''))


def parameter_overrides(node) -> dict:
    """The node's parameter-file entries, name -> rclpy Parameter (mutable: rclpy reads it
    when a parameter is declared)."""
    return node._parameter_overrides
