"""The node command lines of a run, shared by ./ipfric run and the launch file (no ROS)."""
from pathlib import Path

import pytest
import yaml

from ipfric_core.physics.params import ConfigError
from ipfric_core.run.nodes import NODES, node_parameters, parse_overrides, ros_args, write_run_scenario

ROOT = Path(__file__).resolve().parents[2]
DEFAULT = ROOT / 'config' / 'default.yaml'


def test_overrides_replace_only_what_is_given(tmp_path):
    o = parse_overrides({'duration': '5', 'time_mode': 'realtime', 'delay': '', 'theta0': ''})
    assert o == {'duration': 5.0, 'time_mode': 'realtime'}
    path = write_run_scenario(DEFAULT, tmp_path, o)
    data = yaml.safe_load(path.read_text())
    sim, ctl = data['sim_node']['ros__parameters'], data['controller_node']['ros__parameters']
    assert (sim['duration'], sim['time_mode'], sim['theta0'], ctl['delay']) == (5.0, 'realtime', 0.02, 0.0)


@pytest.mark.parametrize('values, message', [
    ({'duration': 'ten'}, 'run argument duration'),
    ({'speed': '1'}, "run argument 'speed' unknown; allowed: duration, time_mode, theta0, delay"),
])
def test_bad_run_arguments_are_named(values, message):
    with pytest.raises(ConfigError, match=message):
        parse_overrides(values)


def test_bad_values_are_refused_before_anything_starts(tmp_path):
    with pytest.raises(ConfigError, match='duration'):
        write_run_scenario(DEFAULT, tmp_path / 'a', {'duration': -1.0})
    with pytest.raises(ConfigError, match='time_mode'):
        write_run_scenario(DEFAULT, tmp_path / 'b', {'time_mode': 'fast'})
    (tmp_path / 'c' / 'bag').mkdir(parents=True)
    with pytest.raises(ConfigError, match='exists already'):
        write_run_scenario(DEFAULT, tmp_path / 'c')


def test_every_node_gets_the_run_scenario_and_its_outputs(tmp_path):
    params = node_parameters(tmp_path / 'scenario.yaml', tmp_path)
    assert list(params) == list(NODES) == ['recorder', 'controller_node', 'sim_node']
    assert ros_args(*params['controller_node']) == [
        '--params-file', str(tmp_path / 'scenario.yaml'), '-p', 'min_command_subscribers:=2',
        '-p', 'use_sim_time:=true']
    assert ros_args(*params['recorder']) == ['-p', f'output:={tmp_path / "bag"}',
                                             '-p', f'scenario_file:={tmp_path / "scenario.yaml"}']
    assert params['sim_node'][1] == {'wait_for_recorder': True, 'result_file': str(tmp_path / 'sim_result.json')}
