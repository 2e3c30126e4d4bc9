"""The paper's loop through ROS: `./ipfric run` records a stick-slip limit cycle, `./ipfric
identify` on its bag finds the stick-slip friction and exports a redesigned gain, which
shrinks the cycle on the same rig."""
import json

import pytest
from rosrun import CONFIG

from ipfric_core.analysis.oscillation import classify
from ipfric_core.analysis.records import load_bag
from ipfric_core.cli import main
from ipfric_core.physics.closedloop import run_closed_loop
from ipfric_core.run.runner import run
from ipfric_core.run.scenario import load_scenario


@pytest.mark.ros
@pytest.mark.slow
def test_identify_on_run_bag_and_redesign(tmp_path, capsys):
    rig = CONFIG / 'fig7_old_gain_exponential.yaml'
    res = run(rig, tmp_path / 'run', duration=15.0, timeout=180)
    assert res.exit_code == 0, res.summary()
    rec = load_bag(tmp_path / 'run')
    assert len(rec.t) == 15001 and rec.theta is not None and rec.gain == pytest.approx(1.7189)
    assert main(['identify', str(tmp_path / 'run'), '--out', str(tmp_path / 'ident'), '--no-plots', '--json',
                 '--export', str(tmp_path / 'identified.yaml'), '--scenario', str(rig), '--rig', str(rig)]) == 0
    r = json.loads(capsys.readouterr().out)
    steps = [s['step'] for s in r['ladder']]
    assert steps == ['declared'] and r['verdict']['explained'], r['verdict']   # the declared law is the rig's
    mu_c = r['identified']['friction']['mu_c']
    assert 0.02 < mu_c < 0.0861  # truth: exponential law, mu_c 0.04287 .. mu_s 0.0861
    assert r['ladder'][-1]['validation']['x_rms_counts'] < 3.0    # the declared law is the rig's: a few counts
    assert not any(p['at_bound'] for p in r['ladder'][-1]['params'])
    before = load_scenario(rig)
    after = load_scenario(r['export']['on_rig'])
    assert after.friction == before.friction and after.truth == before.truth  # same rig, new gain
    p2p = []
    for sc in (before, after):
        tr = run_closed_loop(sc.make_rig(), sc.make_controller(), 15.0)
        p2p.append(classify(tr.t, tr.measured[:, 0], tr.measured[:, 1]).x_p2p)
    assert p2p[1] < 0.6 * p2p[0], p2p
