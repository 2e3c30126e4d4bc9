import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'src' / 'ipfric_core'))

from ipfric_core.design.paperconfig import load_paper_config  # noqa: E402


@pytest.fixture(scope='session')
def paper_cfg():
    return load_paper_config(ROOT / 'config' / 'paper.yaml')


@pytest.fixture(scope='session')
def data_dir():
    return ROOT.parent / 'shared' / 'data'
