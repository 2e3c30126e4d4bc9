"""Delay / initial-angle sweeps: classes, resume without redoing cells, determinism."""
from pathlib import Path

import numpy as np
import pytest

from ipfric_core.run.scenario import load_scenario
from ipfric_core.study.sweep import boundaries, grid, load_cells, parse_range, sweep
from ipfric_core.study.variants import exact_sensors

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope='module')
def fig9_exact():
    s = load_scenario(ROOT / 'config' / 'fig9_new_gain_exponential.yaml')
    return exact_sensors(s)


def test_small_map_has_the_three_regions(fig9_exact, tmp_path):
    taus, ths = parse_range('0:0.04:0.02'), np.array([1.0])
    rows = sweep(fig9_exact, taus, ths, 20.0, tmp_path, workers=2)
    assert grid(rows, taus, ths) == [['settled', 'limit_cycle', 'fallen']]
    b = boundaries(rows, taus, ths)[0]
    assert b['last_settled_tau_s'] == 0.0 and b['first_fallen_tau_s'] == 0.04


def test_resume_skips_finished_cells_and_is_deterministic(fig9_exact, tmp_path):
    taus, ths = np.array([0.0, 0.02]), np.array([1.0])
    first = sweep(fig9_exact, taus, ths, 5.0, tmp_path, workers=1)
    text = (tmp_path / 'cells.csv').read_text()
    # simulate an interruption: keep the first cell and half a line
    lines = text.splitlines()
    (tmp_path / 'cells.csv').write_text('\n'.join(lines[:2]) + '\n' + lines[2][:10])
    assert len(load_cells(tmp_path / 'cells.csv')) == 1
    calls = []
    again = sweep(fig9_exact, taus, ths, 5.0, tmp_path, workers=1, progress=lambda d, t: calls.append(d))
    assert calls[0] == 1                      # one cell was already done
    assert [r['class'] for r in again] == [r['class'] for r in first]
    assert (tmp_path / 'cells.csv').read_text() == text


def test_range_parsing():
    np.testing.assert_allclose(parse_range('0:0.14:0.005')[[0, -1]], [0.0, 0.14])
    assert len(parse_range('0:12:0.5')) == 25
    with pytest.raises(ValueError, match='start:stop:step'):
        parse_range('0:1:-1')


@pytest.mark.parametrize('name', ['fig9_new_gain_exponential.yaml', 'delay_exponential_tau20ms.yaml'])
def test_scenario_writes_back_as_the_same_params_file(name, tmp_path):
    """A sweep cell's ROS parameter file loads back to the very scenario it was made from."""
    import yaml

    from ipfric_core.study.variants import cell_scenario
    scn = cell_scenario(load_scenario(ROOT / 'config' / name), np.float64(0.015), np.float64(2.5))
    path = tmp_path / 'cell.yaml'
    path.write_text(yaml.safe_dump(scn.to_ros_params()))
    back = load_scenario(path)
    assert back == scn
    assert back.controller.delay == 0.015 and back.sim.theta0 == pytest.approx(np.radians(2.5))


def test_figure_12_sweep_reproduces_section_5(tmp_path):
    """`./ipfric sweep --figure 12`: effective critical delay near 0.022-0.028 s for 1 < theta0 < 5 deg,
    rising to the linear tau_c (0.107 s) as theta0 -> 0; both panels drawn from one command."""
    import json

    from ipfric_core.cli import main
    out = tmp_path / 'fig12'
    assert main(['sweep', '--figure', '12', '--tau', '0.015,0.02,0.025,0.03,0.1,0.105,0.11', '--json',
                 '--out', str(out)]) == 0
    s = json.loads((out / 'summary.json').read_text())
    full = {b['theta0_deg']: b for b in s['variants']['dynamic']['full']['boundaries']}
    zoom = {b['theta0_deg']: b for b in s['variants']['dynamic']['zoom']['boundaries']}
    for th in (2.5, 3.0, 4.0, 4.5):
        assert full[th]['first_unsettled_tau_s'] == 0.02 and full[th]['first_fallen_tau_s'] == 0.03
    assert zoom[0.025]['last_settled_tau_s'] == 0.105 and zoom[0.025]['first_fallen_tau_s'] == 0.11
    assert (out / 'figure12.png').stat().st_size > 20_000


@pytest.mark.slow
def test_figure_11_tanh_transitions_coalesce_for_small_angles(tmp_path):
    """Section 5: with tanh(100 v) the two transition delays coalesce for small theta0 and approach
    tau_c = 0.1069 s; with sgn the cart oscillates before the pendulum falls."""
    import json

    from ipfric_core.cli import main
    out = tmp_path / 'fig11'
    assert main(['sweep', '--figure', '11', '--tau', '0.01,0.02,0.03,0.04,0.05,0.1,0.105,0.11', '--json',
                 '--out', str(out)]) == 0
    s = json.loads((out / 'summary.json').read_text())
    tanh = {b['theta0_deg']: b for b in s['variants']['tanh(100v)']['zoom']['boundaries']}
    sgn = {b['theta0_deg']: b for b in s['variants']['sgn']['zoom']['boundaries']}
    assert tanh[0.05]['last_settled_tau_s'] == 0.1 and tanh[0.05]['first_fallen_tau_s'] == 0.105
    assert tanh[0.025]['first_unsettled_tau_s'] == tanh[0.025]['first_fallen_tau_s'] == 0.11
    assert sgn[0.1]['first_unsettled_tau_s'] == 0.04 and sgn[0.1]['first_fallen_tau_s'] == 0.1
