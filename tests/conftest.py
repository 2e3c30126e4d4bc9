import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'src' / 'ipfric_core'))

from ipfric_core.design.paperconfig import load_paper_config  # noqa: E402


def pytest_collection_modifyitems(items):
    """Every test under tests/ros starts ROS 2 nodes: it gets the ``ros`` marker."""
    ros_dir = ROOT / 'tests' / 'ros'
    for item in items:
        if ros_dir in item.path.parents:
            item.add_marker(pytest.mark.ros)


@pytest.fixture(scope='session')
def paper_cfg():
    return load_paper_config(ROOT / 'config' / 'paper.yaml')


@pytest.fixture(scope='session')
def data_dir():
    return ROOT.parent / 'shared' / 'data'
