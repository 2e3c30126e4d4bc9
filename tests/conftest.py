"""What every test shares: the ``ros`` marker of tests/ros, the paper's configuration, the shared data
(skipped when absent). ipfric_core is installed in the environment (editable, by scripts/setup.sh)."""
from pathlib import Path

import pytest

from ipfric_core.design.paperconfig import DEFAULT_DATA, load_paper_config

ROOT = Path(__file__).resolve().parents[1]


#: the files (groups) that take minutes in the default run, longest first (``./ipfric test --durations=0`` on
#: the 2-core machine, 2026-12-06: 482, 289, 191, 132, 75 s): handed out first, so that the workers end together
LONGEST_FIRST = ('tests/ident/test_campaign_fixed.py', 'tests/ros', 'tests/ident/test_identify.py',
                 'tests/ident/test_independent.py', 'tests/study/test_branch_ends.py')


#: files whose every test is a unit of its own (each a whole identification in a process of its own)
EACH_A_UNIT = ('tests/ident/test_campaign_fixed.py',)


def group(nodeid: str) -> str:
    """A test's file, or tests/ros for every file there."""
    path = nodeid.split('::', 1)[0]
    return 'tests/ros' if path.startswith('tests/ros/') else path


def unit(nodeid: str) -> str:
    """The unit a test runs in on a worker: its group, or the test itself in a file of EACH_A_UNIT."""
    return nodeid if group(nodeid) in EACH_A_UNIT else group(nodeid)


def pytest_collection_modifyitems(items):
    """Every test under tests/ros starts ROS 2 nodes: it gets the ``ros`` marker. The groups of
    LONGEST_FIRST come first, in that order (the rest as collected)."""
    ros_dir = ROOT / 'tests' / 'ros'
    for item in items:
        if ros_dir in item.path.parents:
            item.add_marker(pytest.mark.ros)
    rank = {u: i for i, u in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(group(item.nodeid), len(rank)))


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``./ipfric test`` on two workers (pytest-xdist): every file is one unit (its module fixtures are
    computed once; each test of EACH_A_UNIT one of its own), and the files of tests/ros are a single unit,
    run one after another on one worker (their runs wait on the wall clock; the few runs of other files that
    start ROS 2 processes may run beside them, each in a domain it holds). The units are handed out in the
    order of the collection (LONGEST_FIRST first), not by their number of tests."""
    from xdist.scheduler import LoadScopeScheduling

    class FileScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return unit(nodeid)
    config.option.loadscopereorder = False
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
