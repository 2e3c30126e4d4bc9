"""Every scenario file is complete for ``ros2 run``/``ros2 launch`` (no ROS needed)."""
from pathlib import Path

import pytest
import yaml

from ipfric_core.run.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = sorted(p for p in (ROOT / 'config').glob('*.yaml') if p.name != 'paper.yaml')


def test_there_are_scenarios():
    assert len(SCENARIOS) >= 7


@pytest.mark.parametrize('path', SCENARIOS, ids=lambda p: p.name)
def test_controller_stamps_in_simulated_time(path):
    """controller_node takes its clock from sim_node's /clock, so VoltageCommand stamps are
    simulated time under ros2 run too; sim_node is the clock and must not wait for one."""
    data = yaml.safe_load(path.read_text())
    assert data['controller_node']['ros__parameters'].get('use_sim_time') is True
    assert data['sim_node']['ros__parameters'].get('use_sim_time', False) is False
    load_scenario(path)


def test_exported_scenarios_are_complete_too():
    params = load_scenario(ROOT / 'config' / 'default.yaml').to_ros_params()
    assert params['controller_node']['ros__parameters']['use_sim_time'] is True
