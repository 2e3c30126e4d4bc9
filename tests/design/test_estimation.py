"""Friction coefficients from the paper's appendix tables (shared/data/paper)."""
import pytest

from ipfric_core.design import paper
from ipfric_core.design.estimation import coulomb_viscous, load_table5, load_table6, static_coefficient
from ipfric_core.physics.params import ConfigError


def test_mu_s_from_table6(paper_cfg, data_dir):
    V = load_table6(data_dir / 'paper' / 'table6_breakaway_voltage.csv')
    r = static_coefficient(paper_cfg.plant, V)
    assert r['mean_voltage'] == pytest.approx(paper.BREAKAWAY_MEAN_V, abs=5e-6)
    assert round(r['mu_s'], 5) == paper.MU_S


def test_table5_flags_the_misprinted_run(data_dir):
    V, v, Va, va, suspect = load_table5(data_dir / 'paper' / 'table5_constant_voltage.csv')
    assert suspect == [(0.8, 0.137, 0.1030)]
    assert len(v) == 23 and len(va) == 10


def test_mu_c_eps_from_table5(paper_cfg, data_dir):
    """Least squares on the row averages; the printed values lie inside its 95 % interval."""
    _, _, Va, va, _ = load_table5(data_dir / 'paper' / 'table5_constant_voltage.csv')
    r = coulomb_viscous(paper_cfg.plant, Va, va)
    assert r['mu_c'] == pytest.approx(0.04480, abs=5e-5)
    assert r['eps'] == pytest.approx(2.3348, abs=5e-4)
    assert abs(r['mu_c'] - paper.MU_C) < 2 * r['mu_c_std']
    assert abs(r['eps'] - paper.EPS) < 2 * r['eps_std']
    # the paper's procedure (mean of pairwise two-point solutions) is sensitive to pairing
    assert r['pairwise_spread']['eps'] > 0.5


def test_bad_table_is_refused(tmp_path):
    p = tmp_path / 't6.csv'
    p.write_text('run,volts\n1,0.3\n')
    with pytest.raises(ConfigError, match='voltage_V'):
        load_table6(p)
