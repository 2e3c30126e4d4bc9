"""The standard errors' check for a sum of squares that is not quadratic (`ident.lsq.quadratic`)."""
import numpy as np

from ipfric_core.ident.lsq import quadratic


def _check(profile, x=0.0, lo=-10.0, hi=10.0):
    """quadratic() on one parameter whose sum of squares is ``profile(z)`` (0 at ``x``), with a Jacobian error
    of 1 and a level of 1 (one standard error costs one level)."""
    return quadratic(lambda z: profile(float(z[0])), np.array([x]), np.array([lo]), np.array([hi]),
                     np.array([1.0]), np.array([1.0]), profile(x), [0])


def test_a_quadratic_sum_of_squares_keeps_the_jacobians_error():
    assert _check(lambda z: z * z) == []


def test_a_side_flat_beyond_two_errors_is_found_at_four():
    """A drive's contact stiffness: quadratic up to two errors above the fit, then nearly flat (it rose by 4
    levels at four errors, where a quadratic rises by 16). At two errors alone it passed."""
    def stiffness(z):
        return z * z if z < 2.0 else 4.0 + 0.1 * (z - 2.0)
    assert _check(stiffness) == [0]
    assert _check(lambda z: z * z if z < 4.5 else 20.0) == []      # flat only beyond the probes: not seen


def test_a_bound_nearer_than_the_probe_scales_the_rise_it_asks_for():
    """A bound 1.5 errors above the fit: the probe stops there and asks for half a quadratic's rise at that
    distance (1.1 levels), not the 2 levels of two errors; the far side is probed in full."""
    assert _check(lambda z: z * z, hi=1.5) == []
    assert _check(lambda z: 0.4 * z * z if z > 0 else z * z, hi=1.5) == [0]
