"""Data as rigs write them: what the loaders take (uneven stamps, overruns, wrapped and
hanging angles, a byte-order mark, gzip) and what they refuse, by name, with exit code 2."""
import gzip
import json

import numpy as np
import pytest

from ipfric_core.analysis.records import load, overruns, upright_angle
from ipfric_core.cli import main
from ipfric_core.physics.params import ConfigError, PlantParams

N = 600


def table(theta=None, t=None, x=None, u=None):
    t = np.arange(N) * 1e-3 if t is None else t
    x = np.round(0.01 * np.sin(2 * np.pi * t) / 4.54e-5) * 4.54e-5 if x is None else x
    u = np.sin(2 * np.pi * 3 * t) if u is None else u
    cols = [t, x, u] + ([theta] if theta is not None else [])
    head = 't,x,voltage' + (',theta' if theta is not None else '')
    return head + '\n' + '\n'.join(','.join(f'{v:.9g}' for v in row) for row in zip(*cols)) + '\n'


GOOD = table()
ROWS = GOOD.splitlines()
# name, file name, content (str or bytes), phrase of the message
REFUSED = [
    ('all-zero voltage', 'zero.csv', table(u=np.zeros(N)), 'voltage is 0 throughout'),
    ('binary file', 'bin.csv', bytes(range(256)) * 8, 'not a text (UTF-8) CSV'),
    ('empty', 'empty.csv', '', 'empty file'),
    ('header only', 'head.csv', 't,x,voltage\n', 'a header and no data rows'),
    ('ragged row', 'ragged.csv', '\n'.join(ROWS[:50] + [ROWS[50] + ',7'] + ROWS[51:]) + '\n', 'row 51 has 4 fields'),
    ('text in a number', 'word.csv', '\n'.join(ROWS[:9] + ['0.008,abc,1'] + ROWS[10:]) + '\n',
     "row 10, column 'x': 'abc' is not a number"),
    ('time in ms', 'ms.csv', table(t=np.arange(N) * 1.0), 'is t in ms'),
    ('1e308 volts', 'huge.csv', '\n'.join(ROWS[:99] + ['0.098,0,1e308'] + ROWS[100:]) + '\n',
     'column voltage is 1e+308 at row 99'),
    ('random .mat', 'rand.mat', bytes(np.random.default_rng(0).integers(0, 256, 4000, dtype=np.uint8)),
     'not a readable MATLAB file'),
    ('empty .mat', 'empty.mat', b'', 'not a readable MATLAB file'),
    ('angle in degrees', 'deg.csv', table(theta=15.0 + 5.0 * np.sin(np.arange(N) * 1e-2)), 'degrees?'),
    # (a constant angle column is a removed pendulum: tests/analysis/test_records.py::test_constant_angle)
    ('no such file', 'missing.csv', None, 'cannot read'),
    ('bad byte on line 52', 'latin1.csv', ('\n'.join(ROWS[:51]) + '\n').encode() + b'0.05,0\xe9,1\n'
     + ('\n'.join(ROWS[52:]) + '\n').encode(), 'line 52, byte column 7: byte 0xe9 is not UTF-8'),
    ('one 9.5 m row', 'spike.csv', '\n'.join(ROWS[:199] + ['0.198,9.5,0.5'] + ROWS[200:]) + '\n',
     'column x jumps from'),
    ('999 V on a 10 V drive', 'volt.csv', '\n'.join(ROWS[:99] + ['0.098,0,999'] + ROWS[100:]) + '\n',
     'column voltage is 999 at row 99; allowed |voltage| <= 100 V'),
    ('time in minutes', 'min.csv', table(t=np.arange(N) * 1e-3 / 60), 'is t in minutes?'),
    ('one angle row of 1.5 rad', 'tspike.csv', table(theta=np.where(np.arange(N) == 300, 1.5, 0.01)),
     'column theta jumps from 0.01 to 1.5 rad at row 301'),
    ('one angle row of 50 rad', 'tspike50.csv', table(theta=np.where(np.arange(N) == 300, 50.0, 0.01)),
     'column theta jumps from 0.01 to'),
    ('underscore in a number', 'under.csv', '\n'.join(ROWS[:9] + ['0.008,0,1_0.5'] + ROWS[10:]) + '\n',
     "row 10, column 'voltage': '1_0.5' is not a number"),
]


@pytest.mark.parametrize('name, fname, content, phrase', REFUSED, ids=[r[0] for r in REFUSED])
def test_bad_data_refused_by_name_with_exit_2(tmp_path, capsys, name, fname, content, phrase):
    path = tmp_path / fname
    if content is not None:
        path.write_bytes(content if isinstance(content, bytes) else content.encode())
    before = sorted(p.name for p in tmp_path.iterdir())
    assert main(['identify', str(path), '--out', str(tmp_path / 'out'), '--no-plots']) == 2
    err = capsys.readouterr().err
    assert phrase in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == before     # nothing written, nothing lost


def test_bom_gzip_and_column_mapping_are_read(tmp_path):
    (tmp_path / 'bom.csv').write_bytes(b'\xef\xbb\xbf' + GOOD.encode())
    with gzip.open(tmp_path / 'log.csv.gz', 'wt') as f:
        f.write(GOOD.replace('t,x,voltage', 'time,cart,u', 1))
    a = load(tmp_path / 'bom.csv', None)
    b = load(tmp_path / 'log.csv.gz', None, {'t': 'time', 'x': 'cart', 'voltage': 'u'})
    assert np.array_equal(a.x, b.x) and len(a.t) == N


def test_overruns_are_found_and_only_the_frozen_readings_marked():
    t = np.arange(20) * 1e-3
    t[10:] += 2e-3                      # the stamp of row 10 jumps by two periods
    x = np.arange(20.0)
    x[11:13] = x[10]                    # rows 11, 12 repeat row 10's reading
    valid = overruns(t, [x])
    assert list(np.flatnonzero(~valid)) == [11, 12]
    jitter = np.arange(20) * 1e-3 + np.random.default_rng(1).uniform(-3e-4, 3e-4, 20)
    assert overruns(np.sort(jitter), [x]).all()    # jitter of +/-0.3 periods is no overrun


def test_wrapped_and_hanging_angles_map_to_upright():
    """Without evidence from the motion (this angle obeys no pendulum), the angle's zero is read from
    where it stays: more than 90 deg from its zero, it is measured from hanging (a balancing rig)."""
    t = np.arange(500) * 1e-3
    th = 0.01 * np.sin(np.linspace(0, 20, 500))
    hanging = np.angle(np.exp(1j * (th + np.pi)))          # pi at upright, wrapped at +/-pi
    up, notes = upright_angle(t, np.zeros(500), hanging, 0.3, 9.8)
    assert np.allclose(up, th) and any('measured from hanging' in n for n in notes)
    assert any('wrapped' in n for n in notes)
    same, notes = upright_angle(t, np.zeros(500), th, 0.3, 9.8)
    assert np.array_equal(same, th) and any('measured from upright' in n for n in notes)


def swinging_pendulum(hanging: bool, l: float = 0.3, g: float = 9.8):
    """A pendulum on a cart, its angle from upright integrated here (semi-implicit Euler, 0.1 ms) from
    (4/3) l th'' = g sin th - x'' cos th, logged every ms: hanging from pi with the cart driven to and fro
    (2 cm at 1.3 Hz, 1 cm at 3.1 Hz), or balanced upright by a cart acceleration of 2 g th + 0.5 th' (no
    position loop) with 1.5 m/s^2 of excitation at 1.7 Hz."""
    h, n = 1e-4, 60000
    t = np.arange(n) * h
    x = v = 0.0
    th, w = (np.pi + 0.1, 0.0) if hanging else (0.02, 0.0)
    xs, ths = np.empty(n), np.empty(n)
    for k in range(n):
        xs[k], ths[k] = x, th
        if hanging:
            w1, w2 = 2 * np.pi * 1.3, 2 * np.pi * 3.1
            a = -w1 ** 2 * 0.02 * np.sin(w1 * t[k]) - w2 ** 2 * 0.01 * np.sin(w2 * t[k])
        else:
            a = 2 * g * th + 0.5 * w + 1.5 * np.sin(2 * np.pi * 1.7 * t[k])
        w += h * 0.75 * (g * np.sin(th) - a * np.cos(th)) / l
        th += h * w
        v += h * a
        x += h * v
    keep = slice(0, n, 10)
    return t[keep], xs[keep], ths[keep]


@pytest.mark.parametrize('hanging', [True, False])
def test_the_angle_convention_is_read_from_the_pendulums_motion(hanging):
    """The same swinging pendulum logged four ways (from upright or from hanging, either sign): each is read
    back as the angle from upright with the paper's sign, the pendulum's equation deciding."""
    t, x, up = swinging_pendulum(hanging)
    assert np.ptp(up) < 1.0
    counts = 2 * np.pi / 4096
    for sign in (1.0, -1.0):
        for zero, offset in (('upright', 0.0), ('hanging', np.pi)):
            column = np.round(np.angle(np.exp(1j * sign * (up - offset))) / counts) * counts
            got, notes = upright_angle(t, np.round(x / 4.54e-5) * 4.54e-5, column, 0.3, 9.8)
            want = up - 2 * np.pi * np.round(np.median(up) / (2 * np.pi))
            assert np.max(np.abs(got - want)) < 2 * counts, (sign, zero, notes)
            assert any('its equation' in n for n in notes)


def test_the_angle_zero_can_be_named(tmp_path):
    """A log that swings up from hanging is read (analysis finds its balanced part); its zero
    can be given instead of recognised."""
    th = np.linspace(np.pi, 0.0, N)          # from hanging to upright, measured from upright
    (tmp_path / 'swing.csv').write_text(table(theta=th))
    assert np.allclose(load(tmp_path / 'swing.csv', None, angle_zero='upright').theta, th)
    (tmp_path / 'hang.csv').write_text(table(theta=th - np.pi))     # the same, measured from hanging
    assert np.allclose(load(tmp_path / 'hang.csv', None, angle_zero='hanging').theta, th)
    with pytest.raises(ConfigError, match='angle zero'):
        load(tmp_path / 'hang.csv', None, angle_zero='sideways')


def test_a_log_beyond_the_row_limit_is_refused_before_it_is_read(tmp_path, monkeypatch):
    from ipfric_core.analysis import records
    monkeypatch.setattr(records, 'MAX_ROWS', 200)
    (tmp_path / 'long.csv').write_text(table())          # 600 rows, over 1.5 times the limit
    with pytest.raises(ConfigError, match='at most 200 are read'):
        load(tmp_path / 'long.csv', None)


def test_constant_angle_column_is_a_removed_pendulum(tmp_path):
    """A rig logs a constant (often 0) in the angle column with its pendulum off: the record is a
    cart-alone record, said in its notes; --cart-alone drops a moving angle too."""
    (tmp_path / 'zero.csv').write_text(table(theta=np.zeros(N)))
    rec = load(tmp_path / 'zero.csv', None)
    assert rec.theta is None and rec.pendulum is None
    assert any('pendulum is off' in n for n in rec.notes)
    assert rec.normal_force == pytest.approx(rec.plant.M * rec.plant.g)
    (tmp_path / 'swing.csv').write_text(table(theta=0.1 * np.sin(np.arange(N) * 1e-2)))
    assert load(tmp_path / 'swing.csv', None).theta is not None
    rec = load(tmp_path / 'swing.csv', None, cart_alone=True)
    assert rec.theta is None and any('--cart-alone' in n for n in rec.notes)


@pytest.mark.parametrize('mangle, words', [
    (lambda d: (d['x'], d['theta']), None),
    (lambda d: (d['theta'], d['x']), 'x and theta look swapped'),
    (lambda d: (d['x'], np.rad2deg(d['theta'])), 'theta looks like degrees'),
])
def test_columns_that_parse_but_cannot_be_right_are_refused(tmp_path, capsys, mangle, words):
    """A closed-loop log of the independent simulator (30 s, the paper's pendulum) read as written, with x
    and theta swapped, and with theta in degrees: the pendulum's own equation tells them apart."""
    from independent import rigsim
    d = rigsim.generate('loop_none')
    x, th = mangle(d)
    path = tmp_path / 'log.csv'
    np.savetxt(path, np.column_stack([d['t'], x, d['voltage'], th]), delimiter=',', header='t,x,voltage,theta',
               comments='', fmt='%.10g')
    code = main(['analyze', str(path), '--no-plots'])
    err = capsys.readouterr().err
    if words is None:
        assert code == 0, err
    else:
        assert code == 2 and words in err and 'allowed' in err, err


@pytest.mark.parametrize('index', [13, 14])
def test_a_balancing_loop_whose_angle_equation_is_blurred_is_read_as_written(tmp_path, capsys, index):
    """Balancing loops of the randomised independent campaign (seed 11: a 35 ms delay, a saturating
    amplifier) tie the cart to the angle, so that one term of the pendulum's equation takes the declared
    size when the columns are read the other way round: neither is refused as swapped (both terms must
    agree for that)."""
    from independent import campaign
    campaign.write_case(tmp_path, 11, index, duration=20.0)
    d = tmp_path / campaign.case_name(index)
    c = json.loads((d / 'truth.json').read_text())['declared_plant']
    plant = PlantParams(**{k: c[k] for k in ('M', 'm', 'l', 'alpha', 'beta')})
    rec = load(d / 'data.csv', plant)
    assert rec.theta is not None and np.ptp(rec.x) < 0.2       # x read as x: centimetres of travel


def test_a_fifo_is_refused_not_read_without_end(tmp_path, capsys):
    import os
    fifo = tmp_path / 'log.csv'
    os.mkfifo(fifo)
    for cmd in (['identify', str(fifo), '--out', str(tmp_path / 'out')], ['analyze', str(fifo), '--no-plots']):
        assert main(cmd) == 2
        assert 'not a regular file' in capsys.readouterr().err


def test_analyze_cuts_a_rig_log_at_its_gap_and_says_so(tmp_path, capsys):
    """A balancing loop's log (independent simulator, 30 s) with 2 s missing after t = 15 s: no balanced
    stretch spans the gap, and the gap is named."""
    from independent import rigsim
    d = rigsim.generate('loop_none')
    t = d['t'] + np.where(d['t'] > 15.0, 2.0, 0.0)
    path = tmp_path / 'log.csv'
    np.savetxt(path, np.column_stack([t, d['x'], d['voltage'], d['theta']]), delimiter=',',
               header='t,x,voltage,theta', comments='', fmt='%.10g')
    assert main(['analyze', str(path), '--no-plots', '--json']) == 0
    r = json.loads(capsys.readouterr().out)['logs'][0]
    assert any('1 gap(s) in the log (longest 2' in n for n in r['notes']), r['notes']
    spans = [(s['start'], s['end']) for s in r['segments']]
    assert len(spans) == 2 and spans[0][1] <= 15.0 + 1e-9 and spans[1][0] >= 17.0, spans


def test_an_angle_whose_equation_does_not_show_is_read_as_written_and_said_so(tmp_path):
    """An angle unrelated to the cart's motion (its equation shows neither term): read as radians from
    upright, with a note that its zero, unit and column could not be checked."""
    walk = np.cumsum(np.random.default_rng(3).normal(0.0, 2e-4, N))
    (tmp_path / 'flat.csv').write_text(table(theta=np.round(walk / 1.5e-3) * 1.5e-3 + 0.01))
    notes = ' '.join(load(tmp_path / 'flat.csv', None).notes)
    assert 'does not show where its angle is zero' in notes and 'nor can degrees or x and theta swapped' in notes
