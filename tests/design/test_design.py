"""The paper's design and stability numbers (sections 3-5)."""
import numpy as np
import pytest

from ipfric_core.design import paper
from ipfric_core.design.critical_delay import critical_delay, delayed_system
from ipfric_core.design.linearize import characteristic_coefficients, closed_form, jacobian
from ipfric_core.design.lqr import controllable_basis, design
from ipfric_core.design.stability import delta_thresholds, rhp_root_count


@pytest.mark.parametrize('name', ['viscous', 'simple', 'exponential', 'dynamic'])
def test_numerical_jacobian_matches_closed_form(paper_cfg, name):
    A, B = jacobian(paper_cfg.plant, paper_cfg.friction[name])
    A2, B2 = closed_form(paper_cfg.plant, paper_cfg.friction[name])
    np.testing.assert_allclose(A, A2, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(B, B2, rtol=1e-9)


@pytest.mark.parametrize('name', ['exponential', 'dynamic'])
def test_characteristic_polynomial_eq19_eq21(paper_cfg, name):
    A, B = jacobian(paper_cfg.plant, paper_cfg.friction[name])
    K = np.zeros(A.shape[0])
    K[:4] = paper.GAIN_15_VISCOUS
    poly = np.poly(A + B @ K[None, :])
    if name == 'dynamic':
        poly = np.polydiv(poly, [1.0, 0.0])[0]  # lambda * quartic
    np.testing.assert_allclose(poly, characteristic_coefficients(
        paper_cfg.plant, paper_cfg.friction[name], paper.GAIN_15_VISCOUS), rtol=1e-6)


@pytest.mark.parametrize('name, printed, rtol', [
    ('viscous', paper.GAIN_15_VISCOUS, 2e-6),
    ('exponential', paper.GAIN_23_EXPONENTIAL, 2e-6),
    ('dynamic', paper.GAIN_25_DYNAMIC, 3e-5),   # see docs/paper-notes.md
])
def test_lqr_gains(paper_cfg, name, printed, rtol):
    d = design(paper_cfg.plant, paper_cfg.friction[name], paper_cfg.Q, paper_cfg.R)
    np.testing.assert_allclose(d.gain, printed, rtol=rtol, atol=1e-4)
    assert np.all(d.closed_loop_eigenvalues().real < 1e-9)


def test_dynamic_reduction_section_4_2(paper_cfg):
    A, B = jacobian(paper_cfg.plant, paper_cfg.friction['dynamic'])
    U, r = controllable_basis(A, B)
    assert r == 4                                  # z - x is the uncontrollable direction
    np.testing.assert_allclose(np.abs(U[4]), np.array([1, 0, 0, 0, 1]) / np.sqrt(2), atol=1e-9)
    d = design(paper_cfg.plant, paper_cfg.friction['dynamic'], paper_cfg.Q, paper_cfg.R)
    # the full design feeds z back with the x gain; the printed (25) keeps z's entry at 0
    assert d.full_gain[4] == pytest.approx(d.full_gain[0])
    assert d.gain[4] == 0.0
    # K' is basis dependent, its norm is not
    assert np.linalg.norm(d.reduced_gain) == pytest.approx(np.linalg.norm(d.full_gain), rel=1e-9)


@pytest.mark.parametrize('gain, printed', [
    (paper.GAIN_15_VISCOUS, paper.EIG_DYNAMIC_GAIN_15),
    (paper.GAIN_25_DYNAMIC, paper.EIG_DYNAMIC_GAIN_25),
])
def test_dynamic_eigenvalues(paper_cfg, gain, printed):
    A, B = jacobian(paper_cfg.plant, paper_cfg.friction['dynamic'])
    K = np.zeros(5)
    K[:4] = gain[:4]
    ours = np.sort_complex(np.linalg.eigvals(A + B @ K[None, :]))
    ref = np.sort_complex(np.array(printed, complex))
    np.testing.assert_allclose(ours.real, ref.real, rtol=2e-4, atol=1e-9)
    np.testing.assert_allclose(np.abs(ours.imag), np.abs(ref.imag), rtol=2e-3, atol=1e-9)


def test_routh_hurwitz_delta_thresholds(paper_cfg):
    th = delta_thresholds(paper_cfg.plant, paper_cfg.friction['exponential'], paper.GAIN_15_VISCOUS)
    assert round(th['unstable_above'], 1) == paper.DELTA_UNSTABLE_ABOVE
    assert int(th['complex_until']) == paper.DELTA_COMPLEX_UNTIL
    assert th['rhp_roots'] == 2
    below = characteristic_coefficients(paper_cfg.plant, paper_cfg.friction['exponential'].replace(delta=60.0),
                                        paper.GAIN_15_VISCOUS)
    assert rhp_root_count(below) == 0


def test_critical_delay_exponential(paper_cfg):
    A, B = jacobian(paper_cfg.plant, paper_cfg.friction['exponential'])
    r = critical_delay(*delayed_system(A, B, paper.GAIN_23_EXPONENTIAL))
    assert r['tau_c'] == pytest.approx(paper.TAU_C_EXPONENTIAL, abs=5e-5)


def test_critical_delay_dynamic(paper_cfg):
    """Printed 0.1169 s; with gain (25) as printed (z not fed back) it is 0.1072 s, with the
    full design gain (z fed back like x) 0.1160 s: docs/paper-notes.md."""
    A, B = jacobian(paper_cfg.plant, paper_cfg.friction['dynamic'])
    printed_gain = critical_delay(*delayed_system(A, B, paper.GAIN_25_DYNAMIC))
    assert printed_gain['tau_c'] == pytest.approx(0.10724, abs=5e-5)
    full = design(paper_cfg.plant, paper_cfg.friction['dynamic'], paper_cfg.Q, paper_cfg.R).full_gain
    assert critical_delay(*delayed_system(A, B, full))['tau_c'] == pytest.approx(0.11598, abs=5e-5)


def test_critical_delay_is_where_a_root_reaches_the_axis(paper_cfg):
    """Check tau_c independently: the delayed loop with a Pade(8) delay changes stability there."""
    import control
    A, B = jacobian(paper_cfg.plant, paper_cfg.friction['exponential'])
    K = np.array(paper.GAIN_23_EXPONENTIAL)

    def stable(tau):
        num, den = control.pade(tau, 8)
        open_loop = control.ss(A, B, K[None, :], 0) * control.tf(num, den)
        loop = control.feedback(open_loop, 1, sign=1)   # V = +K x(t - tau)
        return np.all(np.real(control.poles(loop)) < 0)
    assert stable(0.105) and not stable(0.109)
