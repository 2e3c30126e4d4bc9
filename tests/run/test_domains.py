"""The ROS domain of a run: every participant's port probed, held by a lock from the check to the
run's end, shared only by rigs in different namespaces (no ROS process started)."""
import socket

import pytest

from ipfric_core.physics.params import ConfigError
from ipfric_core.run.runner import DomainLock, claim_domain, domain_in_use, pick_domain


def test_a_domain_is_in_use_when_any_participant_port_is_taken():
    domain = pick_domain()
    assert not domain_in_use(domain)
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(('0.0.0.0', 7400 + 250 * domain + 10 + 2 * 3))      # participant 3 alone (0-2 have left)
        assert domain_in_use(domain)


def test_two_runs_never_hold_the_same_domain():
    held = [claim_domain() for _ in range(5)]
    try:
        assert len({lock.domain for lock in held}) == 5
        with pytest.raises(ConfigError, match=f'--domain: ROS domain {held[0].domain} is in use by another '
                                              r'./ipfric run; give another'):
            claim_domain(held[0].domain)
        with pytest.raises(ConfigError, match='in use by another ./ipfric run at the root namespace'):
            claim_domain(held[0].domain, '/rig1')
    finally:
        for lock in held:
            lock.release()
    again = claim_domain(held[0].domain)     # released: free again
    again.release()


def test_rigs_in_different_namespaces_share_a_domain_but_not_a_namespace():
    domain = pick_domain()
    rig1, rig2 = claim_domain(domain, '/rig1'), claim_domain(domain, '/rig2')
    try:
        with pytest.raises(ConfigError, match=f'namespace /rig1 of ROS domain {domain} is in use by another'):
            claim_domain(domain, '/rig1')
        with pytest.raises(ConfigError, match=f'ROS domain {domain} is in use by another ./ipfric run;'):
            claim_domain(domain)                                    # the root would meet both rigs
    finally:
        rig1.release()
        rig2.release()
    lock = DomainLock(domain)
    assert lock.acquire() is None
    lock.release()


def test_the_last_domain_is_probed_within_the_port_range():
    assert domain_in_use(232) in (True, False)
