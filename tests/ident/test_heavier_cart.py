"""An alpha correction on the cart alone read as the heavier cart it equals (ident/hypotheses.py:
heavier_cart), on a record of the independent simulator (tests/independent): the same motion, so that a
drive with play can be tried in its place as in place of a mass correction."""
import pytest
from independent import rigsim

from ipfric_core.analysis.records import load
from ipfric_core.ident.hypotheses import heavier_cart, hypotheses
from ipfric_core.ident.model import LAW_PARAMS, load_declared
from ipfric_core.ident.problem import Problem

LAW = LAW_PARAMS['exponential']


@pytest.fixture(scope='module')
def pe(tmp_path_factory):
    rec = load(rigsim.write_case('cart_none', tmp_path_factory.mktemp('heavier'), duration=30.0), None, cart_alone=True)
    return Problem(rec.split(0.6)[0])


@pytest.mark.parametrize('beta_free', [False, True])
def test_an_alpha_correction_on_the_cart_alone_is_the_same_motion_as_a_heavier_cart(pe, beta_free):
    """alpha at 0.8 of the declared value, an offset beside it, the viscous term in eps or (eps held at 0) in
    beta: the heavier cart has alpha as declared, M / 0.8, every force and the viscous term / 0.8, and
    replays the record as the correction does (paper eq. 2 divided through)."""
    declared = load_declared(None, 'exponential', False)
    viscous = ('beta',) if beta_free else ()
    current = declared.with_effect('offset', {'offset_N': 0.05}).with_values(
        {'alpha': 0.8 * declared['alpha'], 'Fc': 0.4, 'Fs_excess': 0.2, 'eps': 0.0 if beta_free else 1.5,
         'beta': 0.9 * declared['beta'] if beta_free else declared['beta']}).with_free(('alpha',) + LAW + viscous)
    heavier = heavier_cart(current, declared, cart_alone=True)
    assert heavier['alpha'] == declared['alpha'] and not heavier.param('alpha').free and heavier.param('M').free
    assert heavier['M'] == pytest.approx(declared['M'] / 0.8)
    assert heavier['Fc'] == pytest.approx(0.5) and heavier['offset_N'] == pytest.approx(0.0625)
    assert heavier['beta'] + heavier['eps'] == pytest.approx((current['beta'] + current['eps']) / 0.8)
    assert heavier.viscous_in_beta == beta_free
    assert pe.cost(heavier) == pytest.approx(pe.cost(current), rel=1e-9)
    assert abs(pe.cost(heavier.with_values({'M': declared['M']})) / pe.cost(heavier) - 1.0) > 0.01   # M matters
    labels = [h.label for h in hypotheses(pe, current, declared, allowed={'drive_backlash'})]
    assert 'drive_backlash in place of alpha corrected' in labels


def test_no_heavier_cart_where_none_is_corrected_or_the_pendulum_tells_m_from_alpha(pe):
    """Not with the pendulum attached (its swing tells the mass from the force per volt), not for an alpha
    above the declared one, not for a lighter cart; a mass correction upwards is itself."""
    declared = load_declared(None, 'exponential', False)
    low = declared.with_values({'alpha': 0.8 * declared['alpha']}).with_free(('alpha',))
    assert heavier_cart(low, declared, cart_alone=False) is None
    assert heavier_cart(low.with_values({'alpha': 1.2 * declared['alpha']}), declared, cart_alone=True) is None
    assert heavier_cart(declared.with_values({'M': 0.9 * declared['M']}).with_free(('M',)), declared, True) is None
    heavy = declared.with_values({'M': 1.2 * declared['M']}).with_free(('M',))
    assert heavier_cart(heavy, declared, cart_alone=True) is heavy
