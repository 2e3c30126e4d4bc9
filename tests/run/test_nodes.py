"""The node command lines of a run, shared by ./ipfric run and the launch file (no ROS)."""
from pathlib import Path

import pytest
import yaml

from ipfric_core.physics.params import ConfigError
from ipfric_core.run.nodes import NODES, REALTIME, node_parameters, parse_overrides, ros_args, write_run_scenario
from ipfric_core.run.scenario import SECTION_KEYS, load_scenario

ROOT = Path(__file__).resolve().parents[2]
DEFAULT = ROOT / 'config' / 'default.yaml'


def sections(path):
    data = yaml.safe_load(Path(path).read_text())
    return data['/**/sim_node']['ros__parameters'], data['/**/controller_node']['ros__parameters']


def test_overrides_replace_only_what_is_given(tmp_path):
    o = parse_overrides({'duration': '5', 'time_mode': 'realtime', 'delay': '', 'theta0': ''})
    assert o == {'duration': 5.0, 'time_mode': 'realtime'}
    path = write_run_scenario(DEFAULT, tmp_path, o)
    sim, ctl = sections(path)
    assert (sim['duration'], sim['time_mode'], sim['theta0'], ctl['delay']) == (5.0, 'realtime', 0.02, 0.0)


def test_the_run_scenario_has_one_wildcard_section_per_node(tmp_path):
    """Whatever keys the user's file has (root, wildcard, a namespace's), the run scenario is the
    sections the nodes in the run's namespace read, merged, under keys that match them anywhere."""
    text = DEFAULT.read_text().replace('/**/sim_node:', '/rig1/sim_node:').replace('/**/controller_node:',
                                                                                    'controller_node:')
    (tmp_path / 'root.yaml').write_text(text)
    with pytest.raises(ConfigError, match=r'no section for controller_node in namespace /rig1 \(write '
                                          r'"/\*\*/controller_node: ros__parameters:"'):
        load_scenario(tmp_path / 'root.yaml', '/rig1')
    with pytest.raises(ConfigError, match=r'no section for sim_node \('):
        load_scenario(tmp_path / 'root.yaml')
    (tmp_path / 'mixed.yaml').write_text('/**:\n  ros__parameters:\n    use_sim_time: false\n'
                                         + text.replace('controller_node:', '/*/controller_node:'))
    path = write_run_scenario(tmp_path / 'mixed.yaml', tmp_path / 'out', namespace='/rig1')
    data = yaml.safe_load(path.read_text())
    assert list(data) == [SECTION_KEYS['sim_node'], SECTION_KEYS['controller_node'], SECTION_KEYS['recorder']]
    assert data[SECTION_KEYS['recorder']] == {'ros__parameters': {'use_sim_time': False}}   # the /** section
    sim, ctl = sections(path)
    assert sim['use_sim_time'] is False and ctl['use_sim_time'] is True and ctl['gain'][0] == 70.7107
    with pytest.raises(ConfigError, match=r'sim_node.ros__parameters: missing field\(s\) friction, plant'):
        write_run_scenario(tmp_path / 'mixed.yaml', tmp_path / 'other', namespace='/rig2')
    assert not (tmp_path / 'other').exists()


@pytest.mark.parametrize('values, message', [
    ({'duration': 'ten'}, 'run argument duration'),
    ({'speed': '1'}, "run argument 'speed' unknown; allowed: duration, time_mode, theta0, delay"),
])
def test_bad_run_arguments_are_named(values, message):
    with pytest.raises(ConfigError, match=message):
        parse_overrides(values)


def test_bad_values_are_refused_before_anything_is_written(tmp_path):
    with pytest.raises(ConfigError, match='duration'):
        write_run_scenario(DEFAULT, tmp_path / 'a', {'duration': -1.0})
    with pytest.raises(ConfigError, match='time_mode'):
        write_run_scenario(DEFAULT, tmp_path / 'b', {'time_mode': 'fast'})
    with pytest.raises(ConfigError, match='theta0'):                   # refused by the schema, not by a file check
        write_run_scenario(DEFAULT, tmp_path / 'b2', {'theta0': 3.0})
    assert not (tmp_path / 'a').exists() and not (tmp_path / 'b').exists() and not (tmp_path / 'b2').exists()
    (tmp_path / 'c' / 'bag').mkdir(parents=True)
    with pytest.raises(ConfigError, match='exists already'):
        write_run_scenario(DEFAULT, tmp_path / 'c')
    assert not (tmp_path / 'c' / 'scenario.yaml').exists()


def test_a_scenario_is_found_by_name(tmp_path):
    path = write_run_scenario('fig9_new_gain_exponential', tmp_path)
    assert load_scenario(path).gain() == [70.7107, 304.9273, 143.3152, 61.0833]
    with pytest.raises(ConfigError, match=r"scenario 'fig99': no such file, and no scenario of that name; by name: "
                                          r'default, delay_exponential_tau20ms, '):
        write_run_scenario('fig99', tmp_path / 'x')


def test_every_node_gets_the_run_scenario_and_its_outputs(tmp_path):
    scenario = write_run_scenario(DEFAULT, tmp_path)
    params = node_parameters(scenario, tmp_path)
    assert list(params) == list(NODES) == ['recorder', 'controller_node', 'sim_node']
    assert ros_args(*params['controller_node']) == ['--params-file', str(scenario), '-p', 'use_sim_time:=true']
    assert ros_args(*params['recorder']) == ['-p', f'output:={tmp_path / "bag"}', '-p', f'scenario_file:={scenario}']
    assert params['sim_node'][1] == {'result_file': str(tmp_path / 'sim_result.json')}
    assert ros_args(*params['sim_node'], namespace='/rig1')[:2] == ['-r', '__ns:=/rig1']


def test_a_realtime_run_gets_the_loop_tuning(tmp_path):
    scenario = write_run_scenario(DEFAULT, tmp_path, {'time_mode': 'realtime'})
    params = node_parameters(scenario, tmp_path)
    for name, extra in REALTIME.items():
        assert params[name][1].items() >= extra.items()
    assert REALTIME['sim_node']['realtime_priority'] > REALTIME['controller_node']['realtime_priority'] > 0
