"""`./ipfric bench --quick`: every benchmark still runs and the table is complete (no timing asserted)."""
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BENCHMARKS = ('closed loop 2 s, Fig. 7', 'closed loop 2 s vs MuJoCo', 'limit cycle error vs scipy',
              'Figure-11 sweep, 9 runs', 'Monte Carlo, 10 runs', 'one periodic orbit', 'orbit branches over the delay',
              'unstable orbit on the edge',
              'ROS lockstep loop', 'ROS realtime 1 kHz', 'analyze a',
              'identify on EMPS', 'identify on a 2-min', 'one simulation of the 20-s 1 kHz closed-loop record',
              'one simulation of a 20-s 1 kHz balancing loop', 'identification campaign: 1 case')


@pytest.mark.ros
@pytest.mark.long       # two minutes or more: every benchmark, a ROS run and a campaign case among them
def test_quick_bench_runs_every_benchmark(tmp_path):
    results = tmp_path / 'RESULTS.md'
    out = subprocess.run([sys.executable, '-m', 'ipfric_core.cli', 'bench', '--quick', '--json',
                          '--results', str(results)], capture_output=True, text=True, cwd=ROOT,
                         env=dict(os.environ), timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    rep = json.loads(out.stdout)
    names = [r['benchmark'] for r in rep['rows']]
    assert len(names) == len(BENCHMARKS)
    for name, want in zip(names, BENCHMARKS):
        assert name.startswith(want), (name, want)
    for i in (0, 1, 3, 4, 5, 6, 7, 8, 13, 14):                      # both sides measured
        assert rep['rows'][i]['ratio'] > 0 and rep['rows'][i]['met'] in (True, False)
    assert 'Machine:' in results.read_text() and '| benchmark | reference | ipfric |' in results.read_text()
