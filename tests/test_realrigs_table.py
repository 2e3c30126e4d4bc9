"""The real-rig table of docs/identification.md (bench/realrigs/identify_all.py): its row of one result.json."""
from bench.realrigs.identify_all import row


def test_the_kept_column_leaves_out_what_the_ladder_took_back():
    """A round keeps an offset, a later step takes it back ('- offset', the ESP32 0.1 Hz trajectory's ladder):
    the row lists what the final model holds, the law, the mass correction and a constant held as declared."""
    params = [{'name': 'Fc', 'value': 0.4451, 'fitted': True, 'at_bound': False},
              {'name': 'Fs_excess', 'value': 0.1903, 'fitted': True, 'at_bound': False}]
    result = {'rounds': [{'kept': 'law coulomb'}, {'kept': 'offset'}, {'kept': 'M corrected'}, {'kept': None}],
              'ladder': [{'step': s, 'params': params}
                         for s in ('declared', 'law coulomb', '+ offset', 'M corrected', 'beta as declared',
                                   '- offset')],
              'constants_corrected': ['M'],
              'verdict': {'explained': False, 'unexplained_percent': 14.94, 'floor_percent': 0.777}}
    r = row('rig', 'log', {'exit': 0, 'wall_s': 1.0}, result)
    assert r['kept'] == 'law coulomb, M corrected, beta as declared'
    assert r['friction'] == '0.445, 0.19' and r['bound'] == 'none'
    assert r['verdict'] == 'not explained: 14.9 % (0.78 %)'


def test_a_log_the_time_limit_stopped_says_so_in_its_row():
    """identify_all --time-limit: a ladder stopped before round 2 is marked in the verdict column."""
    params = [{'name': 'Fc', 'value': 1.2, 'fitted': False, 'at_bound': False},
              {'name': 'Fs_excess', 'value': -0.59, 'fitted': True, 'at_bound': False}]
    result = {'rounds': [{'kept': 'law dynamic'}], 'ladder': [{'step': s, 'params': params}
                                                           for s in ('declared', 'law dynamic')],
              'verdict': {'explained': False, 'unexplained_percent': 38.2, 'floor_percent': 0.04,
                          'stopped': {'before_round': 2, 'time_limit_s': 1200.0, 'elapsed_s': 1630.0}}}
    r = row('rig', 'log', {'exit': 0, 'wall_s': 1700.0}, result)
    assert r['verdict'] == 'not explained: 38.2 % (0.04 %); stopped before round 2 (--time-limit 1200)'
    assert r['kept'] == 'law dynamic' and r['friction'] == '1.2 (held), -0.59'
