"""`./ipfric design --json` and `./ipfric stability --json` print ipfric's and the paper's numbers."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def cli(*args):
    out = subprocess.run([sys.executable, '-m', 'ipfric_core.cli', *args], capture_output=True, text=True,
                         cwd=ROOT, env={'PYTHONPATH': str(ROOT / 'src' / 'ipfric_core'), 'PATH': '/usr/bin:/bin'})
    return out


def test_design_json_side_by_side(data_dir):
    out = cli('design', '--json', '--data', str(data_dir))
    assert out.returncode == 0, out.stderr
    rep = json.loads(out.stdout)
    for name in ('viscous', 'exponential', 'dynamic'):
        assert rep['gains'][name]['max_rel_diff'] < 3e-5
    assert round(rep['friction_estimates']['mu_s']['ipfric'], 5) == 0.08328
    assert rep['controllability_rank']['dynamic'] == {'rank': 4, 'n_states': 5}


def test_design_without_the_data_gives_the_gains_and_says_what_is_left_out(tmp_path):
    out = cli('design', '--data', str(tmp_path / 'nowhere'))
    assert out.returncode == 0, out.stderr
    assert 'exponential model, eq. (23)' in out.stdout and 'Table 6' not in out.stdout
    assert f'{tmp_path / "nowhere" / "paper"} is absent' in out.stderr


def test_stability_json_side_by_side():
    out = cli('stability', '--json')
    rep = json.loads(out.stdout)
    assert round(rep['routh_hurwitz_gain_15_exponential']['unstable_above_delta']['ipfric'], 1) == 60.4
    assert abs(rep['critical_delay_s']['exponential']['ipfric'] - 0.1069) < 5e-5
    assert rep['critical_delay_s']['dynamic']['paper'] == 0.1169


def test_bad_config_is_a_clear_error(tmp_path):
    bad = tmp_path / 'p.yaml'
    bad.write_text((ROOT / 'config' / 'paper.yaml').read_text().replace('model: dynamic', 'model: bristle'))
    out = cli('design', '--config', str(bad))
    assert out.returncode == 2
    assert "friction.dynamic.model: 'bristle' is not one of viscous, coulomb, exponential, dynamic" in out.stderr


@pytest.mark.ros
@pytest.mark.slow
def test_demo_runs_the_default_scenario_and_analyses_it(tmp_path):
    """The README's main job: a closed-loop ROS run of config/default.yaml, then its analysis."""
    out = tmp_path / 'demo'
    r = subprocess.run([str(ROOT / 'ipfric'), 'demo', '--json', '--duration', '12', '--out', str(out)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    res = json.loads(r.stdout)
    assert res['run']['end_reason'] == 'END' and res['run']['samples'] == 12001
    a = res['analysis']
    assert a['class'] == 'limit_cycle' and a['gain'] == [70.7107, 142.5409, 50.6911, 26.9817]
    assert 8e-3 < a['x_p2p'] < 3e-2
    assert (out / 'analysis.json').exists() and Path(a['figure']).exists()
