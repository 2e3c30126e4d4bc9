"""A rig's log analysed per balanced stretch: the record is made here, by code that shares
nothing with ipfric_core (a cart wandering without a period, a stick-slip limit cycle for
20 s, settling), sampled every 5 ms, quantized as the rig's encoders, the angle measured
from hanging and wrapped to (-pi, pi]."""
import json
import math

import numpy as np
import pytest

from ipfric_core.cli import main

DT = 0.005
X_COUNT, TH_COUNT = 4.54e-5, 2 * math.pi / 4096
PERIOD = 2.7          # [s] of the limit cycle
SPANS = {'hanging': (0, 5), 'irregular': (5, 30), 'limit_cycle': (30, 50), 'settled': (50, 70), 'down': (70, 80)}


def wander(n, rng, tau=1.0, std=0.02, corner_hz=2.0):
    """Cart position [m]: an Ornstein-Uhlenbeck walk (time constant tau, std ``std``), low-passed."""
    w = np.zeros(n)
    sigma = std * math.sqrt(2 / tau)
    for k in range(1, n):
        w[k] = w[k - 1] - DT * w[k - 1] / tau + sigma * math.sqrt(DT) * rng.standard_normal()
    a = DT * 2 * math.pi * corner_hz
    for k in range(1, n):
        w[k] = w[k - 1] + a * (w[k] - w[k - 1])
    return w


def rig_log(path, seed, header=('t', 'x', 'voltage', 'theta')):
    """Write the record; return its time and the angle from upright (before quantization)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0, 80, DT)
    x, up = np.zeros_like(t), np.full_like(t, math.pi)      # hanging at the start and the end
    span = {k: (t >= a) & (t < b) for k, (a, b) in SPANS.items()}
    n = int(span['irregular'].sum())
    x[span['irregular']] = wander(n, rng)
    x0 = x[span['irregular']][-1]
    tc = t[span['limit_cycle']] - SPANS['limit_cycle'][0]
    x[span['limit_cycle']] = x0 + 0.007 * np.clip(1.6 * np.sin(2 * np.pi * tc / PERIOD), -1, 1)  # plateaus: sticking
    x1 = x[span['limit_cycle']][-1]
    ts = t[span['settled']] - SPANS['settled'][0]
    x[span['settled']] = x1 + 0.004 * (1 - np.exp(-ts / 0.5))
    x[span['down']] = x[span['settled']][-1]
    balanced = span['irregular'] | span['limit_cycle'] | span['settled']
    up[balanced] = -0.05 * (x[balanced] - np.mean(x[balanced])) + 0.002 * np.sin(2 * np.pi * t[balanced] / PERIOD)
    up[span['settled']] *= np.exp(-(t[span['settled']] - 50) / 0.5)
    up[~balanced] += 0.05 * np.sin(2 * np.pi * 0.9 * t[~balanced])   # swinging while hanging
    hanging = np.angle(np.exp(1j * (up + math.pi)))
    q = np.column_stack([t, np.round(x / X_COUNT) * X_COUNT, 20 * x, np.round(hanging / TH_COUNT) * TH_COUNT])
    np.savetxt(path, q, delimiter=',', header=','.join(header), comments='', fmt='%.9g')
    return t, up


def analyse(capsys, *args):
    code = main(['analyze', *map(str, args), '--no-plots', '--json'])
    out, err = capsys.readouterr()
    return code, (json.loads(out) if code == 0 else err)


@pytest.mark.parametrize('seed', [1, 2, 3])
def test_balanced_stretch_and_its_regimes(tmp_path, capsys, seed):
    rig_log(tmp_path / 'rig.csv', seed)
    code, out = analyse(capsys, tmp_path / 'rig.csv')
    assert code == 0
    log = out['logs'][0]
    assert log['angle_zero'] == 'hanging' and log['sample_period_s'] == pytest.approx(DT)
    assert log['count_size'][0] == pytest.approx(X_COUNT, rel=1e-3)
    [seg] = log['segments']
    assert seg['start'] == pytest.approx(5.0, abs=0.05) and seg['end'] == pytest.approx(70.0, abs=0.05)
    assert seg['class'] == 'settled'
    cycles = [g for g in seg['regimes'] if g['cls'] == 'limit_cycle']
    [cycle] = cycles                                      # the cycle holds only for 30-50 s
    assert cycle['start'] == pytest.approx(30.0, abs=4.0) and cycle['end'] == pytest.approx(50.0, abs=4.0)
    assert cycle['period_crossings'] == pytest.approx(PERIOD, rel=0.03)
    assert cycle['period_spectrum'] == pytest.approx(PERIOD, rel=0.05)
    assert cycle['x_p2p'] == pytest.approx(0.014, abs=2 * X_COUNT)
    assert cycle['stick_fraction'] > 0.3                  # the clipped sine: plateaus at both ends
    wandering = [g for g in seg['regimes'] if g['end'] <= 31.0]
    assert wandering and all(g['cls'] == 'irregular' for g in wandering)
    assert sum(g['end'] - g['start'] for g in wandering) > 20.0
    assert max(g['x_p2p'] for g in wandering) > 0.03      # several centimetres, not settled
    assert seg['regimes'][-1]['start'] < 56.0


def test_columns_angle_zero_and_bad_input(tmp_path, capsys):
    rig_log(tmp_path / 'rig.csv', 1, header=('time_s', 'cart_m', 'u_V', 'angle_rad'))
    code, out = analyse(capsys, tmp_path / 'rig.csv', '--columns', 't=time_s,x=cart_m,voltage=u_V,theta=angle_rad')
    assert code == 0 and len(out['logs'][0]['segments']) == 1
    # the same angle taken as measured from upright: the hanging stretches look balanced
    code, out = analyse(capsys, tmp_path / 'rig.csv', '--columns', 't=time_s,x=cart_m,voltage=u_V,theta=angle_rad',
                        '--angle-zero', 'upright')
    assert code == 0
    assert [(round(s['start']), round(s['end'])) for s in out['logs'][0]['segments']] == [(0, 5), (70, 80)]
    code, err = analyse(capsys, tmp_path / 'rig.csv')
    assert code == 2 and "missing column 't'" in err and '--columns t=NAME' in err
    code, err = analyse(capsys, tmp_path / 'rig.csv', '--columns', 'time=time_s')
    assert code == 2 and "'time=time_s' is not NAME=HEADER" in err and 't, x, voltage, theta' in err
    np.savetxt(tmp_path / 'cart.csv', np.column_stack([np.arange(300) * DT, np.arange(300) * 1e-4, np.ones(300)]),
               delimiter=',', header='t,x,voltage', comments='')
    code, err = analyse(capsys, tmp_path / 'cart.csv')
    assert code == 2 and 'no pendulum angle' in err and '--columns theta=NAME' in err


@pytest.mark.parametrize('args, words', [
    (['--max-angle-deg', '-5'], ['--max-angle-deg', '-5.0', '(0, 90] deg']),
    (['--max-angle-deg', 'nan'], ['--max-angle-deg', 'nan', '(0, 90] deg']),
    (['--max-angle-deg', '400'], ['--max-angle-deg', '400.0', '(0, 90] deg']),
    (['--min-balanced-s', '-1'], ['--min-balanced-s', '-1.0', '(0, 1e+06] s']),
    (['--min-balanced-s', 'inf'], ['--min-balanced-s', 'inf']),
])
def test_bad_thresholds_name_the_option_and_range(args, words, tmp_path, capsys):
    rig_log(tmp_path / 'rig.csv', 1)
    code, err = analyse(capsys, tmp_path / 'rig.csv', *args)
    assert code == 2 and all(w in err for w in words), err


def test_a_file_for_plots_is_refused(tmp_path, capsys):
    rig_log(tmp_path / 'rig.csv', 1)
    f = tmp_path / 'plots'
    f.write_text('x')
    assert main(['analyze', str(tmp_path / 'rig.csv'), '--plots', str(f)]) == 2
    assert f'--plots: {f} is a file; allowed: a directory (new or existing)' in capsys.readouterr().err
