"""The code stays lint-clean (ruff) and the whole source tree type-checks (mypy: the core with its
command line, the ROS packages and bench/, as configured in pyproject.toml)."""
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_ruff_check_is_clean():
    out = subprocess.run([sys.executable, '-m', 'ruff', 'check', '--no-cache', '.'],
                         cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr


@pytest.mark.slow
def test_mypy_is_clean_on_the_source_tree(tmp_path):
    out = subprocess.run([sys.executable, '-m', 'mypy', '--cache-dir', str(tmp_path)],
                         cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr
    assert 'Success' in out.stdout and 'source files' in out.stdout
