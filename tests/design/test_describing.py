"""Describing-function prediction of the hunting: closed forms, python-control's own search, gain (15)."""
import math
from pathlib import Path

import control
import numpy as np
import pytest
from scipy.special import dawsn

from ipfric_core.design.describing import (
    FrictionNonlinearity,
    friction_loop,
    harmonic_balance,
    hunting_over_delays,
    hunting_over_gain_scales,
    predict_hunting,
)
from ipfric_core.physics.params import FrictionParams, PlantParams
from ipfric_core.run.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope='module')
def fig7():
    return load_scenario(ROOT / 'config' / 'fig7_old_gain_exponential.yaml')


def test_relay_on_a_third_order_plant_gives_the_textbook_cycle():
    """Ideal Coulomb friction (a relay of level d) around K / (s (s+1) (s+2)): the Nyquist curve crosses
    the negative real axis at w = sqrt 2 with H = -K / 6, and N(a) = 4 d / (pi a), so a = 4 d K / (6 pi)."""
    d, gain = 0.5, 10.0
    relay = FrictionNonlinearity(FrictionParams(model='coulomb', eps=0.0, mu_s=0.1, mu_c=0.1), d / 0.1)
    assert control.describing_function(relay, 0.3) == pytest.approx(4 * d / (math.pi * 0.3), rel=1e-9)
    h = control.tf([gain], [1, 3, 2, 0])
    (a, w), = harmonic_balance(lambda om: h(1j * om), relay, np.geomspace(0.01, 100, 2000))
    assert w == pytest.approx(math.sqrt(2), rel=1e-9)
    assert a == pytest.approx(4 * d * gain / (6 * math.pi), rel=1e-9)


def test_stribeck_describing_function_is_the_dawson_closed_form(fig7):
    """gamma = 2: N(a) = (4 F_N / (pi a)) (mu_c + (mu_s - mu_c) D(a / v_s) / (a / v_s)), D Dawson's
    function; python-control's sampled evaluation of the same law agrees."""
    f, fn = fig7.friction, fig7.plant.normal_force
    nl = FrictionNonlinearity(f, fn)
    for a in (1e-4, 0.01, 0.1, 1.0):
        r = a / f.v_s
        exact = 4 * fn / (math.pi * a) * (f.mu_c + (f.mu_s - f.mu_c) * dawsn(r) / r)
        assert control.describing_function(nl, a).real == pytest.approx(exact, rel=1e-8)
        sampled = control.describing_function(lambda v: nl(v), a, num_points=2000, try_method=False)
        assert sampled.real == pytest.approx(exact, rel=1e-4)


def test_gain_15_hunting_matches_python_control_and_the_reference(fig7):
    """Figure 7 (gain (15) on the exponential stick-slip plant, no delay): cart 1.63 cm peak to peak,
    period 2.46 s (python-control's search measured elsewhere: 1.63 cm, 2.44 s; the exact loop with
    exact sensors: 1.45 cm, 5.05 s)."""
    r = predict_hunting(fig7.plant, fig7.friction, fig7.gain())
    assert r['intersection'] and len(r['intersections']) == 1
    assert r['x_p2p_m'] == pytest.approx(0.01633, rel=2e-3)
    assert r['period_s'] == pytest.approx(2.464, rel=2e-3)
    assert r['theta_p2p_rad'] == pytest.approx(0.00853, rel=5e-3)
    # the same intersection found by control.describing_function_response on the rational loop
    A, B, bf = friction_loop(fig7.plant, fig7.friction)
    h = control.ss(A + B @ np.asarray(fig7.gain())[None, :], bf, [[0, 0, 1, 0]], 0)
    nl = FrictionNonlinearity(fig7.friction, fig7.plant.normal_force)
    resp = control.describing_function_response(h, nl, np.geomspace(1e-3, 1.0, 200),
                                                omega=np.geomspace(0.1, 100, 2000))
    (a, w), = resp.intersections
    assert a == pytest.approx(r['velocity_amplitude_mps'], rel=1e-3)
    assert w == pytest.approx(r['omega_rad_s'], rel=1e-3)


def test_curves_over_delay_and_gain(fig7):
    """The curve over the delay shortens the period as tau grows; a purely viscous plant has no cycle."""
    rows = hunting_over_delays(fig7.plant, fig7.friction, fig7.gain(), [0.0, 0.02, 0.04])
    assert [r['delay_s'] for r in rows] == [0.0, 0.02, 0.04]
    periods = [r['period_s'] for r in rows]
    assert periods[0] > periods[1] > periods[2]
    scaled = hunting_over_gain_scales(fig7.plant, fig7.friction, fig7.gain(), [1.0])
    assert scaled[0]['x_p2p_m'] == rows[0]['x_p2p_m']
    viscous = predict_hunting(PlantParams(), FrictionParams(model='viscous', eps=3.0), fig7.gain())
    assert viscous == {'intersection': False, 'reason': 'no intersection'}
    with pytest.raises(ValueError, match='internal state'):
        predict_hunting(PlantParams(), FrictionParams(model='dynamic', mu_s=0.1, mu_c=0.05), fig7.gain())
