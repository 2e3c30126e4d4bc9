"""Every scenario file is complete for ``ros2 run``/``ros2 launch`` (no ROS needed)."""
from pathlib import Path

import pytest
import yaml

from ipfric_core.physics.params import ConfigError
from ipfric_core.run.scenario import key_matches, load_scenario

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = sorted(p for p in (ROOT / 'config').glob('*.yaml') if p.name != 'paper.yaml')


def test_there_are_scenarios():
    assert len(SCENARIOS) >= 7


@pytest.mark.parametrize('path', SCENARIOS, ids=lambda p: p.name)
def test_controller_stamps_in_simulated_time(path):
    """controller_node takes its clock from sim_node's /clock, so VoltageCommand stamps are
    simulated time under ros2 run too; sim_node is the clock and must not wait for one."""
    data = yaml.safe_load(path.read_text())
    assert data['/**/controller_node']['ros__parameters'].get('use_sim_time') is True
    assert data['/**/sim_node']['ros__parameters'].get('use_sim_time', False) is False
    load_scenario(path)


def test_exported_scenarios_are_complete_too():
    params = load_scenario(ROOT / 'config' / 'default.yaml').to_ros_params()
    assert params['/**/controller_node']['ros__parameters']['use_sim_time'] is True


@pytest.mark.parametrize('path', SCENARIOS, ids=lambda p: p.name)
def test_every_section_matches_its_node_in_any_namespace(path):
    """The ROS wildcard keys: the same file serves a rig at the root and one in /rig1 (ros2 run
    -r __ns:=/rig1, a launch with PushRosNamespace)."""
    data = yaml.safe_load(path.read_text())
    assert set(data) == {'/**/sim_node', '/**/controller_node'}
    assert load_scenario(path, '/rig1') == load_scenario(path) == load_scenario(path, '/lab/rig2')


@pytest.mark.parametrize('key, node, match', [
    ('/**/sim_node', '/sim_node', True), ('/**/sim_node', '/rig1/sim_node', True),
    ('/**/sim_node', '/a/b/sim_node', True), ('sim_node', '/sim_node', True), ('sim_node', '/rig1/sim_node', False),
    ('/rig1/sim_node', '/rig1/sim_node', True), ('/rig1/sim_node', '/rig2/sim_node', False),
    ('/*/sim_node', '/rig1/sim_node', True), ('/*/sim_node', '/sim_node', False), ('/**', '/rig1/recorder', True),
    ('/**/sim_node', '/rig1/controller_node', False),
])
def test_section_keys_match_as_rcl_matches_them(key, node, match):
    assert key_matches(key, node) is match


def test_an_array_of_two_types_is_refused_as_rcl_refuses_it(tmp_path):
    """rcl's parameter parser refuses [70, 142.5409, ...]; the nodes would die on it after start-up."""
    (tmp_path / 's.yaml').write_text((ROOT / 'config' / 'default.yaml').read_text().replace('gain: [70.7107',
                                                                                               'gain: [70'))
    with pytest.raises(ConfigError, match=r"controller_node.ros__parameters.gain: \[70, 142.5409, 50.6911, 26.9817\] "
                                          r"mixes float, int; a ROS parameter array has one type"):
        load_scenario(tmp_path / 's.yaml')
