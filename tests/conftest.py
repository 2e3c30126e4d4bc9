import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'src' / 'ipfric_core'))

from ipfric_core.design.paperconfig import DEFAULT_DATA, load_paper_config  # noqa: E402


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
    """../shared/data: the paper's appendix tables and the EMPS records; skip when it is absent."""
    if not DEFAULT_DATA.is_dir():
        pytest.skip(f'../shared/data is absent: {DEFAULT_DATA} (appendix tables, EMPS records) is not on this machine')
    return DEFAULT_DATA
