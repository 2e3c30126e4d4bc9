"""What every test shares: the ``ros`` marker of tests/ros, the paper's configuration, the shared data
(skipped when absent). ipfric_core is installed in the environment (editable, by scripts/setup.sh)."""
from pathlib import Path

import pytest

from ipfric_core.design.paperconfig import DEFAULT_DATA, load_paper_config

ROOT = Path(__file__).resolve().parents[1]


def pytest_collection_modifyitems(items):
    """Every test under tests/ros starts ROS 2 nodes: it gets the ``ros`` marker."""
    ros_dir = ROOT / 'tests' / 'ros'
    for item in items:
        if ros_dir in item.path.parents:
            item.add_marker(pytest.mark.ros)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``./ipfric test`` on two workers (pytest-xdist): every file is one unit (its module fixtures are
    computed once), and the files of tests/ros are a single unit, run one after another on one worker
    (their runs wait on the wall clock; the few runs of other files that start ROS 2 processes may run
    beside them, each in a domain it holds)."""
    from xdist.scheduler import LoadScopeScheduling

    class FileScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            path = nodeid.split('::', 1)[0]
            return 'tests/ros' if path.startswith('tests/ros/') else path
    return FileScheduling(config, log)


@pytest.fixture(scope='session')
def paper_cfg():
    return load_paper_config(ROOT / 'config' / 'paper.yaml')


@pytest.fixture(scope='session')
def data_dir():
    """../shared/data: the paper's appendix tables and the EMPS records; skip when it is absent."""
    if not DEFAULT_DATA.is_dir():
        pytest.skip(f'../shared/data is absent: {DEFAULT_DATA} (appendix tables, EMPS records) is not on this machine')
    return DEFAULT_DATA
