"""What a kept plant correction tells the user (ladder.correction_notes): the declared value beside the
data's, and the readings of the same model that the data cannot tell apart."""
from ipfric_core.ident.ladder import correction_notes
from ipfric_core.ident.model import load_declared


def corrected(k_m, k_a, pendulum=True):
    declared = load_declared(None, 'exponential', pendulum)
    model = declared.freeing(['M', 'alpha']).with_values({'M': k_m * declared['M'], 'alpha': k_a * declared['alpha']})
    return declared, model


def test_M_and_alpha_by_one_factor_name_the_wrong_pendulum_mass_they_equal():
    declared, model = corrected(1.31, 1.32)
    notes = correction_notes(declared, model, {'M': 0.006, 'alpha': 0.01}, cart_alone=False)
    assert notes[0].startswith(f'the declared M is {declared["M"]:.4g} kg')
    scaled = [n for n in notes if 'pendulum mass' in n]
    assert len(scaled) == 1
    assert f'{declared["m"] / 1.315:.4g} kg instead of the declared {declared["m"]:.4g} kg' in scaled[0]


def test_M_and_alpha_by_different_factors_or_without_errors_get_no_such_note():
    declared, model = corrected(1.31, 1.05)
    errors = {'M': 0.006, 'alpha': 0.01}
    assert not [n for n in correction_notes(declared, model, errors, False) if 'pendulum mass' in n]
    declared, model = corrected(1.31, 1.31)
    assert not [n for n in correction_notes(declared, model, {}, False) if 'pendulum mass' in n]
