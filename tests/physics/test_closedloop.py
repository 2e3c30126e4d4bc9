"""Offline closed loop of the paper's experiments (Figures 7, 9, 10) on the physics core."""
import math

import numpy as np
import pytest

from ipfric_core.constants import ANGLE_RESOLUTION_RAD, CART_RESOLUTION_M
from ipfric_core.design import paper
from ipfric_core.physics.closedloop import run_closed_loop
from ipfric_core.physics.controller import StateFeedback, delay_samples
from ipfric_core.physics.encoder import quantize
from ipfric_core.physics.plant import CartPendulum
from ipfric_core.physics.rig import PlantTruth, Rig

PAPER_RES = (CART_RESOLUTION_M, ANGLE_RESOLUTION_RAD)


def run(cfg, friction, gain, theta0, duration=30.0, res=(0.0, 0.0), delay=0.0):
    rig = Rig(CartPendulum(cfg.plant, cfg.friction[friction]), PlantTruth(), [0.0, theta0, 0.0, 0.0],
              1e-3, res)
    return run_closed_loop(rig, StateFeedback(gain, 1e-3, delay), duration)


def test_old_gain_on_stick_slip_plant_oscillates(paper_cfg):
    """Figure 7: a limit cycle of the cart of order a centimetre, with sticking phases."""
    tr = run(paper_cfg, 'exponential', paper.GAIN_15_VISCOUS, 0.02, res=PAPER_RES)
    late = tr.t > 15
    p2p = np.ptp(tr.state[late, 0])
    assert tr.end_reason == 'duration'
    assert 0.008 < p2p < 0.03
    assert 0.1 < tr.stuck[late].mean() < 0.6


@pytest.mark.parametrize('friction, gain, theta0', [
    ('exponential', paper.GAIN_23_EXPONENTIAL, 0.06),   # Figure 9
    ('dynamic', paper.GAIN_25_DYNAMIC, 0.02),           # Figure 10
])
def test_new_gains_settle(paper_cfg, friction, gain, theta0):
    tr = run(paper_cfg, friction, gain, theta0)
    late = tr.state[tr.t > 20]
    assert np.ptp(late[:, 0]) < 1e-6 and np.abs(late[:, 1]).max() < 1e-6


def test_quantization_leaves_small_oscillation(paper_cfg):
    """Section 6: with the paper's encoders the stabilized loop keeps a small motion,
    far below the old gain's limit cycle."""
    tr = run(paper_cfg, 'exponential', paper.GAIN_23_EXPONENTIAL, 0.06, res=PAPER_RES)
    late = tr.state[tr.t > 20]
    assert 1e-5 < np.ptp(late[:, 0]) < 0.008


def test_large_delay_makes_the_pendulum_fall(paper_cfg):
    tr = run(paper_cfg, 'exponential', paper.GAIN_23_EXPONENTIAL, math.radians(3), duration=10, delay=0.06)
    assert tr.end_reason == 'FALLEN'


def test_delay_is_exact_in_samples():
    c = StateFeedback([1.0, 0, 0, 0], 1e-3, delay=0.003, cutoff_hz=0)
    out = [c.update(x, 0.0) for x in (1.0, 2.0, 3.0, 4.0, 5.0)]
    assert out == [1.0, 1.0, 1.0, 1.0, 2.0]   # history of eq. (30), then x(t - 3 dt)
    assert delay_samples(0.025, 1e-3) == 25
    with pytest.raises(ValueError, match='not a multiple of the sample period'):
        delay_samples(0.0105, 1e-3)


def test_controller_rejects_z_gain_and_saturates():
    with pytest.raises(ValueError, match='entry 4'):
        StateFeedback([1, 2, 3, 4, 5], 1e-3)
    c = StateFeedback([100.0, 0, 0, 0], 1e-3, voltage_limit=5.0)
    assert c.update(1.0, 0.0) == 5.0


def test_encoder_rounds_to_counts():
    assert quantize(0.0012, 0.0005) == pytest.approx(0.001)
    assert quantize(-0.00026, 0.0005) == pytest.approx(-0.0005)
    assert quantize(0.123, 0.0) == 0.123
