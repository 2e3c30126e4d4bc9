import math

import numpy as np
import pytest

from ipfric_core.physics.friction import (
    Friction,
    bristle_path,
    friction_vector,
    sliding_friction,
    static_friction,
    stribeck_level,
)
from ipfric_core.physics.params import FrictionParams

FN = (0.815 + 0.21) * 9.8
EXP = FrictionParams('exponential', eps=3.0, mu_s=0.0861, mu_c=0.04287, v_s=0.105, gamma=2.0)
DYN = FrictionParams('dynamic', eps=3.0, mu_s=0.0861, mu_c=0.04287, v_s=0.105, gamma=2.0,
                     sigma0=121.0, sigma1=70.0)


def test_viscous_eq3():
    f = Friction(FrictionParams('viscous', eps=2.1), FN)
    assert f.force(0.2) == pytest.approx(-0.42)
    assert not f.sticks and f.static_limit == 0.0


def test_coulomb_viscous_eqs_6_7():
    f = Friction(FrictionParams('coulomb', eps=2.3156, mu_s=0.08328, mu_c=0.04287), FN)
    assert f.force(0.1) == pytest.approx(-0.04287 * FN - 0.23156)
    assert f.force(-0.1) == pytest.approx(0.04287 * FN + 0.23156)
    assert f.sticks and f.static_limit == pytest.approx(0.08328 * FN)


def test_static_eq5():
    lim = 0.0861 * FN
    assert static_friction(0.5, lim) == -0.5
    assert static_friction(-2.0, lim) == pytest.approx(lim)
    f = Friction(EXP, FN)
    assert f.holds(0.99 * lim) and not f.holds(1.01 * lim)


def test_stribeck_eq8_limits():
    f = Friction(EXP, FN)
    assert f.level(0.0) == pytest.approx(0.0861 * FN)            # static level at rest
    assert f.level(10.0) == pytest.approx(0.04287 * FN)          # Coulomb level when fast
    v = 0.105                                                     # at v_s: exp(-1)
    assert stribeck_level(v, 0.0861, 0.04287, 0.105, 2.0, FN) == pytest.approx(
        (0.04287 + (0.0861 - 0.04287) / math.e) * FN)
    assert f.force(0.05) == pytest.approx(-f.level(0.05) - 0.15)
    assert f.force(0.0, direction=-1.0) == pytest.approx(0.0861 * FN)


def test_tanh_smoothing_and_linear_slope():
    f = Friction(EXP.replace(smoothing='tanh', delta=100.0), FN)
    assert not f.sticks
    assert f.force(1e-6) == pytest.approx(-(3.0 + 100 * 0.0861 * FN) * 1e-6, rel=1e-6)
    assert f.slope_at_rest() == pytest.approx(3.0 + 100 * 0.0861 * FN)


def test_dynamic_steady_state_equals_exponential():
    """Section 2.2: at constant v, z -> g(v) sgn(v)/sigma0 and F -> eq. (8)."""
    f = Friction(DYN, FN)
    for v in (0.02, 0.1, -0.3):
        z = f.level(v) * math.copysign(1, v) / 121.0
        assert f.z_rate(v, z) == pytest.approx(0.0, abs=1e-12)
        assert f.force(v, z) == pytest.approx(Friction(EXP, FN).force(v), rel=1e-12)


def test_steady_sliding_friction_is_eq8_whatever_the_bristles_damping():
    """The force of steady sliding (the report's friction at the speeds the cart moved at) is eq. (8) for the
    dynamic law too: the bristles' damping sigma1 acts only while z moves. A real log's fit (sigma1 16686 N s/m)
    was reported with 4249 N at 0.255 m/s, the bristles taken at rest (z = 0)."""
    for sigma1 in (70.0, 16686.0):
        fp = friction_vector(DYN.replace(sigma1=sigma1), FN)
        for v in (0.00781, 0.0371, 0.255, -0.1):
            g = (0.04287 + (0.0861 - 0.04287) * math.exp(-(abs(v) / 0.105) ** 2)) * FN
            assert sliding_friction(fp, v) == pytest.approx(-math.copysign(g, v) - 3.0 * v, rel=1e-12)
    fp = friction_vector(EXP, FN)
    assert sliding_friction(fp, 0.05) == pytest.approx(Friction(EXP, FN).force(0.05), rel=1e-12)


def test_bristle_path_is_eq10_solved_exactly_and_holds_at_rest():
    """The bristles along held velocities (the equation-error path's friction): eq. (10) at constant v is
    z' = v - a z, a = sigma0 |v| / g(v), so z(t) = z_ss (1 - exp(-a t)) from rest, z_ss = g(v) sgn(v) / sigma0;
    a zero velocity holds z."""
    fp = friction_vector(DYN, FN)
    v, dt = -0.02, 1e-3
    g = (0.04287 + (0.0861 - 0.04287) * math.exp(-(abs(v) / 0.105) ** 2)) * FN
    a, z_ss = 121.0 * abs(v) / g, -g / 121.0
    z = bristle_path(fp, np.array([v] * 5 + [0.0] * 3), dt)
    for k in range(5):
        assert z[k] == pytest.approx(z_ss * (1.0 - math.exp(-a * dt * (k + 1))), rel=1e-12)
    assert list(z[5:]) == [z[4]] * 3


def test_dynamic_presliding_is_a_spring():
    f = Friction(DYN, FN)
    assert f.force(0.0, 1e-3) == pytest.approx(-0.121)
    assert f.z_rate(1e-3, 0.0) == pytest.approx(1e-3)


def test_asymmetric_static_limits_and_sliding_levels():
    """a = 0.5: static friction holds up to 1.5 mu_s F_N forward and 0.5 mu_s F_N backward;
    sliding levels (1 +/- a) g(v); dF_v adds to eps forward and subtracts backward."""
    p = FrictionParams(model='coulomb', eps=1.0, mu_s=0.1, mu_c=0.05, asymmetry=0.5, asymmetry_viscous=0.4)
    f = Friction(p, 10.0)
    assert f.holds(1.49) and not f.holds(1.51)
    assert f.holds(-0.49) and not f.holds(-0.51)
    assert f.force(0.5) == pytest.approx(-1.5 * 0.5 - (1.0 + 0.4) * 0.5)
    assert f.force(-0.5) == pytest.approx(0.5 * 0.5 + (1.0 - 0.4) * 0.5)
