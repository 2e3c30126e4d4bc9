"""The numba cache: outside the source tree, one directory per source version, stale ones pruned."""
import os
import subprocess
import sys
import time
from pathlib import Path

from ipfric_core.physics import compiled

ROOT = Path(__file__).resolve().parents[2]
CORE = ROOT / 'src' / 'ipfric_core'


def test_cache_root_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv('IPFRIC_CACHE_DIR', str(tmp_path / 'mine'))
    assert compiled.cache_root() == tmp_path / 'mine'
    monkeypatch.delenv('IPFRIC_CACHE_DIR')
    monkeypatch.setenv('XDG_CACHE_HOME', str(tmp_path / 'xdg'))
    assert compiled.cache_root() == tmp_path / 'xdg' / 'ipfric'
    monkeypatch.delenv('XDG_CACHE_HOME')
    monkeypatch.setenv('HOME', str(tmp_path / 'home'))
    assert compiled.cache_root() == tmp_path / 'home' / '.cache' / 'ipfric'


def test_prune_removes_only_stale_caches_of_other_versions(tmp_path):
    now = time.time()
    old = now - compiled.STALE_AFTER_S - 60
    current, stale, fresh, other = (tmp_path / n for n in ('numba-current', 'numba-stale', 'numba-fresh', 'notes'))
    for d in (current, stale, fresh, other):
        (d / 'sub').mkdir(parents=True)
    for d in (current, stale, other):
        os.utime(d, (old, old))
    assert compiled.prune(tmp_path, current, now) == [stale]
    assert sorted(p.name for p in tmp_path.iterdir()) == ['notes', 'numba-current', 'numba-fresh']


def test_compiled_code_is_cached_outside_the_source_tree(tmp_path):
    before = set(CORE.rglob('numba-*'))
    code = ('from ipfric_core.physics.encoder import quantize\n'
            'from ipfric_core.physics.compiled import CACHE_DIR\n'
            'assert quantize(0.26, 0.1) == 0.30000000000000004\n'
            'print(CACHE_DIR)')
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True, cwd=tmp_path,
                         env={**os.environ, 'IPFRIC_CACHE_DIR': str(tmp_path / 'cache'), 'PYTHONPATH': str(CORE)})
    assert out.returncode == 0, out.stderr
    cache = Path(out.stdout.strip())
    assert cache.parent == tmp_path / 'cache' and cache.name == f'numba-{compiled.source_key()}'
    assert any(cache.rglob('*.nbi')) and any(cache.rglob('*.nbc'))   # numba's index and machine code
    assert set(CORE.rglob('numba-*')) == before
