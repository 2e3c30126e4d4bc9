"""The code stays lint-clean (ruff) and the core type-checks (mypy), as configured in pyproject.toml."""
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
# every layer of the core
TYPED = ['ipfric_core.constants', 'ipfric_core.physics', 'ipfric_core.design', 'ipfric_core.run',
         'ipfric_core.analysis', 'ipfric_core.ident']


def test_ruff_check_is_clean():
    out = subprocess.run([sys.executable, '-m', 'ruff', 'check', '--no-cache', '.'],
                         cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr


@pytest.mark.slow
def test_mypy_is_clean_on_the_core_layers(tmp_path):
    packages = [a for p in TYPED for a in ('-p', p)]
    out = subprocess.run([sys.executable, '-m', 'mypy', '--cache-dir', str(tmp_path), *packages],
                         cwd=ROOT / 'src' / 'ipfric_core', capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr
