"""The order in which a round's passing explanations are confirmed (judging.leaner_first), on stand-in
models whose validation errors and floors are given: the rule alone, without a fit."""
from types import SimpleNamespace

import pytest

from ipfric_core.ident import judging


def judged(name, n_free, score):
    model = SimpleNamespace(name=name, free=[object()] * n_free)
    return judging.Judged(SimpleNamespace(label=name), model, 0.0, 0.0, score, [])


@pytest.fixture
def errors(monkeypatch):
    """Validation errors [counts] by model name, and the models :func:`judging.verdict` calls explained."""
    table = {'error': {}, 'explained': set()}
    pv = SimpleNamespace(summary=lambda m: {'x_rms_counts': table['error'][m.name]})
    monkeypatch.setattr(judging, 'verdict', lambda _pv, m: {'explained': m.name in table['explained']})
    return table, pv


def test_a_leaner_explanation_at_its_floor_goes_first_within_the_verdicts_tolerance(errors):
    """Seed 2027 case 11, a clean balancing loop: the refit (4 parameters) leaves 27.6 counts, at its
    floor; a lag (5) lowers that to 22.1. The data cannot tell them apart: the refit is confirmed first."""
    table, pv = errors
    lag, refit = judged('lag', 5, 1.0), judged('refit', 4, 2.0)
    table['error'].update(lag=22.1, refit=27.6)
    assert judging.leaner_first([lag, refit], pv) == [lag, refit]      # the refit not at its floor: the lag
    table['explained'].add('refit')
    assert judging.leaner_first([lag, refit], pv) == [refit, lag]


def test_a_leaner_explanation_far_above_the_best_stays_behind_even_at_its_own_floor(errors):
    """A stiff bristle law whose own floor is high reaches it at 76 counts; a mass correction leaves 2:
    beyond EXPLAINED_FACTOR of the best error, the leaner one is no match, whatever its floor."""
    table, pv = errors
    best, lean = judged('M corrected', 5, 1.0), judged('law dynamic', 4, 9.0)
    table['error'].update({'M corrected': 2.0, 'law dynamic': 76.0})
    table['explained'].add('law dynamic')
    assert judging.leaner_first([best, lean], pv) == [best, lean]
    table['error']['law dynamic'] = judging.EXPLAINED_FACTOR * 2.0 + judging.EXPLAINED_SLACK
    assert judging.leaner_first([best, lean], pv) == [lean, best]


def test_extra_parameters_must_earn_the_gain_an_effect_must(errors):
    """Without any floor reached, a leaner explanation within SIM_GAIN_PERCENT of the best goes first."""
    table, pv = errors
    best, lean = judged('bristles', 6, 1.0), judged('refit', 4, 1.1)
    table['error'].update(bristles=10.0, refit=10.0 / (1 - judging.SIM_GAIN_PERCENT / 100) * 0.999)
    assert judging.leaner_first([best, lean], pv) == [lean, best]
    table['error']['refit'] = 10.5
    assert judging.leaner_first([best, lean], pv) == [best, lean]
