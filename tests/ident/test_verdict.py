"""The verdict (ident/judging.verdict) on a record of the independent simulator: the error left and what
the encoders' rounding alone would leave, both in % of the measured motion."""
import pytest
from independent import rigsim

from ipfric_core.analysis.records import load
from ipfric_core.ident.judging import verdict
from ipfric_core.ident.model import load_declared
from ipfric_core.ident.problem import Problem


def test_the_floor_is_a_share_of_the_measured_motion_even_for_a_model_that_hardly_moves(tmp_path):
    rec = load(rigsim.write_case('cart_none', tmp_path, duration=20.0), None)
    pv = Problem(rec.split(0.6)[1])
    model = load_declared(None, 'exponential', pendulum=False)
    stuck = model.with_values({'Fc': 8 * model['Fc'], 'Fs_excess': 8 * model['Fs_excess']})   # hardly moves
    got = {}
    for name, m in (('declared', model), ('stuck', stuck)):
        v = got[name] = verdict(pv, m)
        # one denominator: the counts' ratio is the percents' ratio
        assert v['floor_percent'] == pytest.approx(v['floor_counts'] * v['unexplained_percent']
                                                   / v['unexplained_counts'], rel=0.05), (name, v)
    assert got['stuck']['unexplained_percent'] > 50       # most of the motion left ...
    assert got['stuck']['floor_percent'] < 5              # ... beside a rounding that leaves a few %, not a share
    assert not got['stuck']['explained']                 # of the little the model moves
