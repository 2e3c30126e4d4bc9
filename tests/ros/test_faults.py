"""Faults of a run with the real node processes: the supervisor or a node killed, hung up,
paused, and a rogue publisher flooding the command topic.

Each test checks: no process of the run left (``ps``), the reason named once, the
documented exit code (runner.py: 1 a node failed, 3 a safety fault, 130 stopped), and a
bag that ``read_run`` reads, its loss stated. Bounds on waits only guard against a hang.
"""
import json
import signal
import subprocess
import sys
import time

import pytest
from rosrun import scenario_file, started

from ipfric_core.analysis.bagread import read_run
from ipfric_core.constants import REPO_ROOT as ROOT
from ipfric_core.run.runner import EXIT_FAULT, Run

pytestmark = pytest.mark.ros
CFG = ROOT / 'config' / 'default.yaml'



def processes_of(out) -> list[str]:
    """Processes whose command line names the run directory ``out`` (``ps``)."""
    ps = subprocess.run(['ps', '-ww', '-eo', 'pid,args'], capture_output=True, text=True).stdout.splitlines()
    return [ln for ln in ps if str(out) in ln and 'ps -ww' not in ln]


def until_gone(out, timeout=60.0) -> list[str]:
    t0 = time.monotonic()
    while processes_of(out) and time.monotonic() - t0 < timeout:
        time.sleep(0.1)
    return processes_of(out)


def runner(out, duration='0', *extra):
    return subprocess.Popen([sys.executable, '-m', 'ipfric_core.cli', 'run', '--config', str(CFG), '--duration',
                             duration, '--out', str(out), '--json', *extra],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)


@pytest.mark.parametrize('sig', [signal.SIGKILL, signal.SIGHUP])
def test_the_nodes_die_with_their_supervisor_and_close_the_bag(tmp_path, sig):
    out = tmp_path / 'run'
    p = runner(out)
    try:
        started(out / 'logs' / 'sim_node.log', p)
        time.sleep(0.5)                   # mid-run (not a discovery wait)
        assert len(processes_of(out)) >= 3
        p.send_signal(sig)
        stdout, _ = p.communicate(timeout=60)
        assert until_gone(out) == []      # no orphan
    finally:
        if p.poll() is None:
            p.kill()
    bag = read_run(out / 'bag')
    assert bag.intact and len(bag.t) > 100      # the recorder closed the bag
    assert bag.end_reason == 'ABORT'
    if sig == signal.SIGKILL:
        assert p.returncode == -signal.SIGKILL
        assert 'supervisor' in bag.events[-1][2] or 'SIGTERM' in bag.events[-1][2], bag.events[-1]
    else:                                 # a closed terminal: a clean stop with its summary
        assert p.returncode == 130
        res = json.loads(stdout)
        assert res['interrupted'] and res['counts_match'] and res['samples'] == len(bag.t)


@pytest.mark.parametrize('node', ['recorder', 'sim_node'])
def test_a_killed_node_is_named_once_and_the_summary_agrees_with_the_bag(tmp_path, node):
    r = Run(CFG, tmp_path / 'run', duration=0.0, timeout=300, grace=5.0)
    r.start()
    try:
        started(r.logs['sim_node'], r.procs['sim_node'])
        mcap = next((tmp_path / 'run' / 'bag').glob('*.mcap'))
        t0 = time.monotonic()
        while mcap.stat().st_size < 2.5e6:          # two 1 MiB chunks on disk
            assert time.monotonic() - t0 < 120, 'the recorder wrote nothing'
            time.sleep(0.1)
        r.procs[node].kill()
        res = r.wait()
    finally:
        r.kill()
    assert res.exit_code == 1
    assert len(res.failures) == 1 and res.failures[0].startswith(f'{node} killed by SIGKILL'), res.failures
    assert until_gone(tmp_path / 'run') == []
    bag = read_run(res.bag)
    assert res.recorded == bag.counts             # the summary says what analyze reads
    if node == 'recorder':
        assert bag.truncated and res.bag_loss and 'not closed by the recorder' in res.bag_loss[0]
        assert len(bag.t) > 100
    else:
        assert bag.intact and bag.end_reason is None   # the simulator could not say why


def test_a_paused_controller_is_a_stall_event_and_a_fault(tmp_path):
    cfg = scenario_file(tmp_path, 'default.yaml', sim={'duration': 8.0})
    r = Run(cfg, tmp_path / 'run', timeout=300)
    r.start()
    ctl = r.procs['controller_node']
    try:
        started(r.logs['sim_node'], r.procs['sim_node'])
        time.sleep(0.5)
        ctl.send_signal(signal.SIGSTOP)
        time.sleep(3.0)                   # the pause itself (what is tested), not a wait
        ctl.send_signal(signal.SIGCONT)
        res = r.wait()
    finally:
        if ctl.poll() is None:
            ctl.send_signal(signal.SIGCONT)
        r.kill()
    assert res.exit_code == EXIT_FAULT, res.summary()
    assert any('stalled 1 time(s)' in f for f in res.faults), res.faults
    assert any('watchdog tripped' in f for f in res.faults), res.faults
    bag = read_run(res.bag)
    codes = [code for _, code, _ in bag.events]
    assert codes.count('STALL') == 1 and 'WATCHDOG' in codes
    assert bag.intact
