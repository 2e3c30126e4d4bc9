"""controller_node's ``executor`` parameter: an unknown executor stops the node with exit
code 2 and names the parameter and the allowed values."""
import pytest
from rosrun import CONFIG, start_node

from ipfric_core.run.runner import pick_domain

pytestmark = pytest.mark.ros


def test_unknown_executor_is_refused(tmp_path):
    log = tmp_path / 'controller_node.log'
    p = start_node('controller_node', ['--params-file', str(CONFIG / 'default.yaml'), '-p', 'executor:=multi'],
                   pick_domain(), log)
    assert p.wait(timeout=60) == 2
    text = log.read_text()
    assert "controller_node.ros__parameters.executor: 'multi'; allowed single_threaded, events" in text
