"""A real recorded bag, cut and with bytes changed at random (fixed seed), read back.

Needs the ROS workspace (the bag is recorded once per session by ``./ipfric run``). The
reader runs in a subprocess (tests/analysis/bagfuzz.py), so a crash fails the test with
its signal. Each damaged copy must be read without a silent change of value (values read
equal the original, or the file is reported truncated or damaged) and ``ipfric analyze``
must exit 0 for an intact file, 1 for a damaged or truncated one, 2 for a refused one.
"""
import json
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from ipfric_core.analysis.bagread import read_run
from ipfric_core.constants import REPO_ROOT as ROOT
from ipfric_core.run.runner import Run

pytestmark = pytest.mark.ros
CUTS, FLIPS, SEED = 200, 200, 12


@pytest.fixture(scope='session')
def recorded_bag(tmp_path_factory) -> Path:
    """The .mcap of an 8 s run of config/default.yaml (3 MB, four 1 MiB chunks)."""
    out = tmp_path_factory.mktemp('recorded') / 'run'
    r = Run(ROOT / 'config' / 'default.yaml', out, duration=8.0, timeout=300)
    r.start()
    try:
        res = r.wait()
    finally:
        r.kill()
    assert res.exit_code == 0, res.summary()
    return next((out / 'bag').glob('*.mcap'))


def test_cuts_and_byte_flips_are_read_without_crash_or_silent_change(recorded_bag, tmp_path):
    ref = read_run(recorded_bag)
    assert ref.intact and len(ref.t) == 8001
    p = subprocess.run([sys.executable, str(Path(__file__).with_name('bagfuzz.py')), str(recorded_bag),
                        str(SEED), str(CUTS), str(FLIPS), str(tmp_path)],
                       capture_output=True, text=True, timeout=900)
    lines = p.stdout.splitlines()
    last = next((ln for ln in reversed(lines) if ln.startswith('start')), 'no case')
    how = signal.Signals(-p.returncode).name if p.returncode < 0 else p.returncode
    assert p.returncode == 0, (f'reader died with {how}'
                               f' at {last}: {p.stderr[-2000:]}')
    cases = [json.loads(ln) for ln in lines if ln.startswith('{')]
    assert len(cases) == CUTS + FLIPS
    for c in cases:
        if 'refused' in c:                       # the magic itself damaged or cut
            assert c['exit'] == 2 and c['at'] < 8, c
            continue
        assert c['exit'] == (0 if c['intact'] else 1), c
        assert c['same'] or not c['intact'], c   # no silent change
        assert c['subset'], c                    # what is read of a damaged file is original
        if c['kind'] == 'cut':
            assert not c['intact'], c
    # cut files keep every message up to the cut: the samples read grow with the cut length
    cuts = sorted((c['at'], c['samples']) for c in cases if c['kind'] == 'cut' and 'refused' not in c)
    assert all(a[1] <= b[1] for a, b in zip(cuts, cuts[1:]))
    assert max(s for _, s in cuts) > 7900
    flips = [c for c in cases if c['kind'] == 'flip']
    assert sum(not c['intact'] for c in flips) > 50       # damage in chunks is found (CRC)
    assert all(c['samples'] >= 8001 - 3100 for c in flips if 'samples' in c)  # one chunk lost at most
