"""The fenced rclpy internals: the version check and what the nodes take through them."""
import re
import time

import pytest
from rosrun import Peer

from ipfric_ros import rclpy_internals
from ipfric_ros.rclpy_internals import RCLPY_SERIES, SubscriptionWaiter, check_version, parameter_overrides


def test_the_installed_rclpy_is_the_checked_series():
    check_version()
    assert rclpy_internals.rclpy_version().startswith(f'{RCLPY_SERIES[0]}.{RCLPY_SERIES[1]}.')


@pytest.mark.parametrize('found', ['9.2.0', '10.0.1', '8.1.0', '?'])
def test_another_rclpy_is_refused_with_a_sentence(found):
    with pytest.raises(RuntimeError, match=re.escape(f'rclpy {found}: ipfric_ros.rclpy_internals was checked '
                                                     f'with rclpy 9.1.x only')):
        check_version(found)


def test_the_waiter_takes_messages_with_their_publisher_gid_and_overrides_are_readable():
    from std_msgs.msg import Float64
    peer = Peer('internals')
    try:
        node = peer.node
        pub = node.create_publisher(Float64, 'fenced', 10)
        sub = node.create_subscription(Float64, 'fenced', lambda m: None, 10)
        waiter = SubscriptionWaiter(node, sub)
        peer.spin_until(lambda: pub.get_subscription_count() == 1, 30, 'the match')
        pub.publish(Float64(data=2.5))
        t0 = time.monotonic()
        got = None
        while got is None and time.monotonic() - t0 < 10:   # a hang guard
            waiter.wait(0.1)
            got = waiter.take()
        msg, gid = got
        assert msg.data == 2.5
        assert gid == bytes(node.get_publishers_info_by_topic('/fenced')[0].endpoint_gid) and len(gid) == 16
        assert waiter.take() is None
        assert parameter_overrides(node) == {}
    finally:
        peer.close()
