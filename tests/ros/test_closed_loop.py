"""The ROS 2 closed loop, real processes over DDS on loopback: `./ipfric run` equivalents.

Each scenario runs once (simulator, controller and recorder as separate processes in a
fresh ROS domain); the tests read the recorded bag back to decide.
"""
import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from rosrun import CONFIG, p2p, scenario_file

from ipfric_core.analysis.bagread import read_run
from ipfric_core.physics.closedloop import run_closed_loop
from ipfric_core.run.runner import run
from ipfric_core.run.scenario import load_scenario
from ipfric_core.study.variants import exact_sensors

DURATION = {'fig7_old_gain_exponential': 15.0, 'fig9_new_gain_exponential': 12.0,
            'fig10_new_gain_dynamic': 12.0}


@pytest.fixture(scope='module')
def runs(tmp_path_factory):
    done = {}

    def get(name):
        if name not in done:
            out = tmp_path_factory.mktemp(name)
            res = run(CONFIG / f'{name}.yaml', out / 'run', duration=DURATION[name], timeout=180)
            assert res.exit_code == 0, res.summary()
            print(f'{name}: {res.samples} samples in {res.wall_time_s:.1f} s wall, '
                  f'{res.steps_per_s:.0f} lockstep samples/s')
            done[name] = (res, read_run(res.bag))
        return done[name]
    return get


@pytest.mark.slow
def test_old_gain_on_exponential_plant_keeps_oscillating(runs):
    """Figure 7: gain (15) on the stick-slip plant, a cart limit cycle of order a centimetre."""
    res, bag = runs('fig7_old_gain_exponential')
    assert res.end_reason == 'END' and bag.end_reason == 'END'
    amp = p2p(bag.t, bag.x)
    assert amp > 8e-3, f'cart p2p over the last 5 s = {amp * 1e3:.2f} mm: no limit cycle'
    assert amp < 5e-2
    # the cart really moves back and forth (several mean crossings in the last 5 s)
    w = bag.t >= bag.t[-1] - 5.0
    x = bag.x[w] - bag.x[w].mean()
    assert np.count_nonzero(np.diff(np.sign(x)) != 0) >= 2


@pytest.mark.slow
def test_new_gains_settle(runs):
    """Figures 9 and 10: gain (23) on the exponential plant and gain (25) on the dynamic plant."""
    old = p2p(*(lambda b: (b.t, b.x))(runs('fig7_old_gain_exponential')[1]))
    for name in ('fig9_new_gain_exponential', 'fig10_new_gain_dynamic'):
        res, bag = runs(name)
        assert res.end_reason == 'END', name
        amp = p2p(bag.t, bag.x)
        assert amp < 5e-3, f'{name}: cart p2p {amp * 1e3:.2f} mm over the last 5 s'
        assert amp < old / 3, f'{name}: {amp * 1e3:.2f} mm is not well below the old gain {old * 1e3:.2f} mm'
        assert np.abs(bag.theta[bag.t >= bag.t[-1] - 5]).max() < np.radians(1.0)


def test_lockstep_equals_offline_closed_loop(runs):
    """Same sample times, quantization and commands as ipfric_core.physics.closedloop, to the last bit."""
    res, bag = runs('fig7_old_gain_exponential')
    scn = load_scenario(f'{res.out}/scenario.yaml')
    tr = run_closed_loop(scn.make_rig(), scn.make_controller(), scn.sim.duration)
    n = len(tr.t)
    assert len(bag.t) == n == res.samples
    k = np.arange(n)
    assert np.max(np.abs(bag.t - k * 1e-3)) < 1e-9            # t_k = k dt
    meas = np.column_stack([bag.x, bag.theta])
    assert np.max(np.abs(meas - tr.measured)) < 1e-9
    assert np.array_equal(bag.command_t, bag.t)              # one command per sample, in order
    assert np.max(np.abs(bag.voltage - tr.voltage)) < 1e-9
    truth = np.column_stack([bag.truth[k] for k in ('x', 'theta', 'x_dot', 'theta_dot')])
    assert np.max(np.abs(truth - tr.state)) < 1e-9
    assert np.max(np.abs(bag.truth['friction_force'] - tr.friction)) < 1e-9
    assert np.array_equal(bag.truth['stuck'].astype(bool), tr.stuck)


def test_recorded_counts_equal_published_counts(runs):
    res, bag = runs('fig7_old_gain_exponential')
    n = res.samples
    diagnostics = (n - 1) // 1000                         # one per second of simulated time
    assert res.published == {'/clock': n, '/joint_states': n, '/plant_state': n, '/safety_event': 2,
                             '/diagnostics': diagnostics}
    assert res.counts_match
    assert bag.counts == {'/clock': n, '/joint_states': n, '/plant_state': n, '/voltage_command': n,
                          '/safety_event': 2, '/controller_gain': 1, '/diagnostics': diagnostics,
                          '/parameter_events': 0}     # the rig's parameter changes: none in this run
    # the controller's own count (logged at its shutdown) equals the recorded commands
    log = (res.out and open(f'{res.out}/logs/controller_node.log').read())
    assert f'published {n} commands' in log
    end = [d for _, code, d in bag.events if code == 'END'][0]
    assert json.loads(end.split('published ', 1)[1]) == res.published


def test_bag_is_rosbag2_mcap_with_configuration(runs):
    res, bag = runs('fig7_old_gain_exponential')
    from mcap.reader import make_reader
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore
    meta = yaml.safe_load(Path(res.bag, 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert meta['version'] == 9 and meta['storage_identifier'] == 'mcap'
    config = json.loads(meta['custom_data']['ipfric.config'])
    assert config['gain'] == [70.7107, 142.5409, 50.6911, 26.9817]
    assert config['friction']['model'] == 'exponential' and config['sim']['duration'] == 15.0
    assert set(config) >= {'plant', 'friction', 'plant_truth', 'sim', 'controller', 'gain'}
    assert bag.config == config and bag.gain == config['gain']
    mcap_path = next(Path(res.bag).glob('*.mcap'))
    with open(mcap_path, 'rb') as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        assert summary.statistics.message_count == sum(bag.counts.values())
        assert {s.encoding for s in summary.schemas.values()} == {'ros2msg'}
        assert {c.message_encoding for c in summary.channels.values()} == {'cdr'}
        assert {m.name for m in reader.iter_metadata()} == {'ipfric', 'rosbag2'}
        log_times = [m.log_time for _, _, m in reader.iter_messages(log_time_order=False)]
        assert all(a <= b for a, b in zip(log_times, log_times[1:]))   # file order = time order
    store = get_typestore(Stores.ROS2_KILTED)
    for path in (Path(res.bag), mcap_path):       # as a bag and as a bare file
        with AnyReader([path], default_typestore=store) as r:
            assert {c.topic: c.msgcount for c in r.connections} == bag.counts
            conn = [c for c in r.connections if c.topic == '/plant_state'][0]
            first = next(r.messages(connections=[conn]))
            assert r.deserialize(first[2], conn.msgtype).sample_index == 0


@pytest.mark.slow
def test_realtime_mode_is_paced_by_the_wall_clock(tmp_path):
    cfg = scenario_file(tmp_path, 'fig9_new_gain_exponential.yaml', sim={'time_mode': 'realtime'})
    res = run(cfg, tmp_path / 'run', duration=1.0, timeout=60)
    assert res.exit_code == 0, res.summary()
    assert res.end_reason == 'END' and res.samples == 1001
    assert 0.9 < res.wall_time_s < 2.0
    assert res.counts_match
    bag = read_run(res.bag)
    assert np.max(np.abs(bag.t - np.arange(1001) * 1e-3)) < 1e-9
    assert abs(bag.theta).max() < 0.2


@pytest.mark.parametrize('name', sorted(p.name for p in CONFIG.glob('*.yaml') if p.name != 'paper.yaml'))
def test_scenario_files_load(name):
    scn = load_scenario(CONFIG / name)
    assert scn.sim.time_mode == ('realtime' if name == 'realtime.yaml' else 'lockstep') and len(scn.gain()) == 4


def test_analyze_finds_the_figure_7_cycle_in_the_bag(runs, tmp_path):
    """`./ipfric analyze` on the recorded run: class, amplitude, two agreeing periods, sticking, plots."""
    from ipfric_core.analysis.recorded_run import analyze_run
    res, _ = runs('fig7_old_gain_exponential')
    a = analyze_run(res.out, tmp_path)
    assert a['class'] == 'limit_cycle' and not a['truncated'] and a['end_reason'] == 'END'
    assert 8e-3 < a['x_p2p'] < 3e-2                       # of order a centimetre (Figure 7)
    assert 1.5 < a['period_crossings'] < 5.0 and a['periods_agree']
    assert abs(a['period_crossings'] - a['period_spectrum']) < 0.1 * a['period_crossings']
    assert a['stick_fraction'] > 0.2                      # the cart sticks during the cycle
    assert Path(a['figure']).parent == tmp_path and Path(a['figure']).stat().st_size > 10_000


def test_truncated_bag_is_read_up_to_its_last_complete_record(runs, tmp_path):
    """A recorder killed mid-write: the reader keeps every complete record and says so."""
    from ipfric_core.analysis.recorded_run import analyze_run
    res, full = runs('fig7_old_gain_exponential')
    data = next(Path(res.bag).glob('*.mcap')).read_bytes()
    cut = tmp_path / 'cut.mcap'
    cut.write_bytes(data[:int(0.6 * len(data)) + 7])      # ends inside a record
    bag = read_run(cut)
    assert bag.truncated and bag.truncation_detail
    n = len(bag.t)
    assert 0.3 * len(full.t) < n < 0.75 * len(full.t)
    assert np.array_equal(bag.x, full.x[:n]) and np.array_equal(bag.theta, full.theta[:n])
    assert bag.end_reason is None                          # the END event was never written
    a = analyze_run(cut)
    assert a['truncated'] and a['class'] == 'limit_cycle'


@pytest.mark.slow
def test_ros_sweep_gives_the_offline_classes(tmp_path):
    """`./ipfric sweep --ros`: cells through the ROS loop classify exactly as the offline core."""

    from ipfric_core.analysis.recorded_run import analyze_run
    from ipfric_core.study.sweep import sweep
    s = load_scenario(CONFIG / 'fig9_new_gain_exponential.yaml')
    s = exact_sensors(s)
    taus, ths = [0.0, 0.06], [3.0]
    ros = sweep(s, taus, ths, 12.0, tmp_path / 'ros', ros=True)
    off = sweep(s, taus, ths, 12.0, tmp_path / 'off', workers=1)
    assert [r['class'] for r in ros] == [r['class'] for r in off] == ['settled', 'fallen']
    for a, b in zip(ros, off):
        assert a['x_p2p_m'] == pytest.approx(b['x_p2p_m'], abs=1e-12)
    bags = sorted((tmp_path / 'ros' / 'ros').glob('*/run'))
    assert [analyze_run(b)['class'] for b in bags] == ['settled', 'fallen']
