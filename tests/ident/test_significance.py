"""The significance a drop of the validation error needs (judging.drop_checks): p < P_VALUE for a hypothesis
of the round's library, p < P_REFINEMENT for a kept effect's refinement (one nested test per kept effect), on
stand-in windows' squared errors whose block bootstrap gives a p-value between the two."""
from types import SimpleNamespace

import numpy as np

from ipfric_core.ident import judging
from ipfric_core.ident.hypotheses import Hypothesis
from ipfric_core.ident.model import load_declared


def windows(before: float, mean_drop: float, spread: float, n: int = 60) -> tuple[np.ndarray, np.ndarray]:
    """Two models' squared errors over ``n`` validation windows: the drop alternates about its mean."""
    sse0 = np.full(n, before)
    return sse0, sse0 - (mean_drop + spread * np.where(np.arange(n) % 2 == 0, 1.0, -1.0))


def stand_in(sse: dict) -> SimpleNamespace:
    """A validation problem whose cost and windows' errors are given per model."""
    return SimpleNamespace(cost=lambda m: float(np.mean(sse[m])), window_sse=lambda m: sse[m], n_windows=60)


def test_a_drop_between_the_two_p_values_counts_for_a_refinement_only():
    """A mean drop of 15 % of the squared error, half the windows dropping by 0.75 and half rising by 0.45:
    p = 0.029, significant for a refinement (P_REFINEMENT 0.05), not for an effect of the library (P_VALUE
    0.01)."""
    sse0, sse1 = windows(1.0, 0.15, 0.6)
    pv = stand_in({'current': sse0, 'opened': sse1})
    p = judging.block_p_value(sse0, sse1)
    assert judging.P_VALUE < p < judging.P_REFINEMENT
    gain, pval, why = judging.drop_checks(pv, 'current', 'opened', sse0)
    assert pval == p and gain > judging.SIM_GAIN_PERCENT
    assert why == [f'the drop is not significant (p = {p:.2g} over 60 windows, needs < {judging.P_VALUE:g})']
    assert judging.drop_checks(pv, 'current', 'opened', sse0, judging.P_REFINEMENT)[2] == []
    # a drop that no window carries more than another is significant under both
    sse0, sse1 = windows(1.0, 0.15, 0.05)
    pv = stand_in({'current': sse0, 'opened': sse1})
    assert judging.drop_checks(pv, 'current', 'opened', sse0)[2] == []


def test_only_a_kept_effect_is_refined():
    """A drive's play opened refines a model that holds the drive; the same hypothesis on a model without it
    adds an effect and is judged as the library's are."""
    declared = load_declared(None, 'exponential', False)
    current = declared.with_effect('drive_backlash')
    h = Hypothesis('drive_backlash with its play opened', 'effect', current, (), (), effect='drive_backlash')
    assert h.refines(current) and not h.refines(declared)
    assert not Hypothesis('refit', 'friction', current, (), ()).refines(current)
