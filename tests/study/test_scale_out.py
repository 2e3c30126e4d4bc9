"""Runs on a Dask cluster give the rows of the local process pool; a dead scheduler is a clear error."""
import socket
import time
from pathlib import Path

import numpy as np
import pytest

from ipfric_core.cli import main
from ipfric_core.run.scenario import load_scenario
from ipfric_core.study.executor import SchedulerError, make_executor
from ipfric_core.study.montecarlo import run_montecarlo, spread_draw
from ipfric_core.study.sweep import sweep
from ipfric_core.study.variants import exact_sensors

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope='module')
def cluster():
    """A Dask cluster on loopback: 2 worker processes of 1 thread, no dashboard."""
    distributed = pytest.importorskip('distributed')
    with distributed.LocalCluster(host='127.0.0.1', n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as c:
        yield c.scheduler_address


@pytest.fixture(scope='module')
def fig9_exact():
    s = load_scenario(ROOT / 'config' / 'fig9_new_gain_exponential.yaml')
    return exact_sensors(s)


def test_sweep_on_the_cluster_gives_the_local_rows(cluster, fig9_exact, tmp_path):
    taus, ths = np.array([0.0, 0.02, 0.04]), np.array([1.0, 3.0])
    local = sweep(fig9_exact, taus, ths, 5.0, tmp_path / 'local', workers=2)
    remote = sweep(fig9_exact, taus, ths, 5.0, tmp_path / 'dask', scheduler=cluster)
    assert remote == local
    assert (tmp_path / 'dask' / 'cells.csv').read_text() == (tmp_path / 'local' / 'cells.csv').read_text()
    assert {r['class'] for r in local} >= {'settled', 'fallen'}


def test_montecarlo_on_the_cluster_gives_the_local_rows(cluster, tmp_path):
    base = load_scenario(ROOT / 'config' / 'default.yaml')

    def draw(i):
        return spread_draw(base, {'mu_s': 0.3, 'mu_c': 0.3, 'eps': 0.3}, 11, i)
    local = run_montecarlo(draw, 30, 5.0, workers=2)
    remote = run_montecarlo(draw, 30, 5.0, scheduler=cluster)
    assert remote == local
    assert len({r['x_p2p_m'] for r in local}) > 10          # the draws differ, and so do the runs


def test_continuation_on_the_cluster_gives_the_local_branches(cluster):
    """The Jacobians' columns in tasks on the cluster: the same points, bit for bit."""
    from ipfric_core.study.continuation import trace
    from ipfric_core.study.variants import loop_of
    s = load_scenario(ROOT / 'config' / 'fig7_old_gain_exponential.yaml')
    base = exact_sensors(s)

    def run(executor):
        found = trace(lambda v: loop_of(base, 'delay', v), 0.0, 0.004, 4, probes=1, partners=False,
                      executor=executor)
        return found.jacobians, [(p.parameter, p.branch, p.orbit.x_p2p, p.orbit.period, tuple(p.orbit.multipliers))
                                 for p in found.points]
    local = run(None)
    with make_executor(cluster) as ex:
        remote = run(ex)
    assert remote == local
    assert len(local[1]) >= 3 and local[0] >= 3
    assert abs(local[1][0][2] - 0.014370) < 1e-5            # Figure 7's stick-slip cycle at delay 0 [m]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(('127.0.0.1', 0))
        return s.getsockname()[1]


@pytest.mark.timeout(60)
def test_unreachable_scheduler_is_a_clear_error(tmp_path, capsys):
    address = f'tcp://127.0.0.1:{free_port()}'
    with pytest.raises(SchedulerError, match='--scheduler'):
        make_executor(address, timeout=1.0)
    code = main(['sweep', '--tau', '0', '--theta0-deg', '1', '--duration', '1', '--scheduler', address,
                 '--out', str(tmp_path / 'out')])
    assert code == 2
    err = capsys.readouterr().err
    assert f'--scheduler {address}' in err and 'no Dask scheduler' in err
    code = main(['orbit', '--config', str(ROOT / 'config' / 'fig7_old_gain_exponential.yaml'), '--simulate', '0',
                 '--continue', 'delay=0:0.002:3', '--scheduler', address, '--no-plots',
                 '--out', str(tmp_path / 'orbit')])
    assert code == 2
    assert f'--scheduler {address}' in capsys.readouterr().err


@pytest.mark.timeout(60)
@pytest.mark.parametrize('says, words', [(None, 'within 1 s'), (b'SSH-2.0-OpenSSH_9.6\r\n', 'is no Dask scheduler')])
def test_a_port_that_is_no_scheduler_is_a_clear_error(says, words):
    """A service that accepts the connection and says nothing, or something else than Dask's handshake:
    refused within the timeout, no Client made (none left to fail at exit)."""
    import threading
    with socket.socket() as srv:
        srv.bind(('127.0.0.1', 0))
        srv.listen()
        held = []

        def accept():
            conn, _ = srv.accept()
            held.append(conn)
            if says:
                conn.sendall(says)
        threading.Thread(target=accept, daemon=True).start()
        t0 = time.monotonic()
        with pytest.raises(SchedulerError, match=words):
            make_executor(f'tcp://127.0.0.1:{srv.getsockname()[1]}', timeout=1.0)
        assert time.monotonic() - t0 < 5.0
        for conn in held:
            conn.close()


@pytest.mark.timeout(60)
@pytest.mark.parametrize('address', ['notahost:xx', 'tcp://', 'http://10.0.0.5:8786', 'tcp://h:99999', 'tcp://a b'])
def test_a_malformed_scheduler_address_is_refused_before_any_work(address, tmp_path, capsys):
    for argv in (['montecarlo', '--spread', 'mu_s=0.3', '--runs', '2'],
                 ['sweep', '--tau', '0', '--theta0-deg', '1', '--duration', '1'],
                 ['orbit', '--continue', 'delay=0:0.002:3', '--simulate', '0']):
        code = main([*argv, '--scheduler', address, '--out', str(tmp_path / 'out')])
        err = capsys.readouterr().err
        assert code == 2 and f'--scheduler: {address!r} is not a scheduler address' in err, err
        assert 'HOST[:PORT] with PORT 1..65535' in err and 'Traceback' not in err
        assert not (tmp_path / 'out').exists()


@pytest.mark.timeout(30)
def test_a_refused_connection_ends_at_once_in_one_line(tmp_path, capsys):
    address = f'127.0.0.1:{free_port()}'
    t0 = time.monotonic()
    assert main(['montecarlo', '--spread', 'mu_s=0.3', '--runs', '2', '--duration', '1', '--scheduler', address,
                 '--out', str(tmp_path / 'out')]) == 2
    err = capsys.readouterr().err
    assert time.monotonic() - t0 < 5 and err.count('\n') == 1 and f'no Dask scheduler answers at {address}' in err
