"""Bad input, one row per case: the command's exit code and a phrase of its message.

Each row gives the files to create (name -> content; ``{cfg}`` in a content is the text of
config/default.yaml) and the argv of ``ipfric`` (``{dir}`` is the row's directory). Every
row also checks that nothing the user had changed and that no run started (no ``logs/``).
CSV and .mat data files of ``identify`` have their rows in tests/ident.
"""
import socket
from pathlib import Path

import pytest

from ipfric_core.cli import main
from ipfric_core.run.runner import pick_domain
from ipfric_core.run.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
CFG = (ROOT / 'config' / 'default.yaml').read_text()
PAPER = (ROOT / 'config' / 'paper.yaml').read_text()


def replaced(old: str, new: str, text: str = CFG) -> str:
    assert old in text
    return text.replace(old, new, 1)


RUN = ['run', '--config', '{dir}/s.yaml', '--out', '{dir}/out']
CASES = [
    # (id, files, argv, exit code, phrase)
    ('config not utf-8', {'s.yaml': replaced('# [rad] initial angle', '# [rad] \xe9').encode('latin-1')}, RUN, 2,
     'line 13: byte 0xe9 is not UTF-8 text'),
    ('plant file not utf-8', {'p.yaml': ('# r\xe9glages\n' + PAPER).encode('latin-1')},
     ['design', '--config', '{dir}/p.yaml'], 2, 'line 1: byte 0xe9 is not UTF-8 text'),
    ('key given twice', {'s.yaml': replaced('    theta0: 0.02', '    theta0: 0.02\n    theta0: 0.03')}, RUN, 2,
     "key 'theta0' given twice, on lines 13 and 14"),
    ('second sim_node section', {'s.yaml': CFG + '\n/**/sim_node:\n  ros__parameters:\n    theta0: 0.1\n'}, RUN, 2,
     "key '/**/sim_node' given twice, on lines 5 and"),
    ('misspelt recorder parameter', {'s.yaml': CFG + '\nrecorder:\n  ros__parameters:\n    outptu: runs/x\n'}, RUN,
     2, "recorder.ros__parameters.outptu: unknown parameter (did you mean 'output'?); allowed: output, scenario_file"),
    ('recorder: 5', {'s.yaml': CFG + '\nrecorder: 5\n'}, RUN, 2,
     'recorder: 5 is not a mapping with ros__parameters:'),
    ('unknown section', {'s.yaml': CFG + '\nsimnode: {}\n'}, RUN, 2,
     "unknown section 'simnode'; allowed: sections for sim_node, controller_node, recorder (e.g. /**/sim_node"),
    ('mixed-type array', {'s.yaml': replaced('gain: [70.7107', 'gain: [70')}, RUN, 2,
     'controller_node.ros__parameters.gain: [70, 142.5409, 50.6911, 26.9817] mixes float, int'),
    ('no section for the namespace', {'s.yaml': replaced('/**/sim_node:', 'sim_node:')},
     RUN + ['--namespace', '/rig1'], 2, 'no section for sim_node in namespace /rig1'),
    ('bad namespace', {'s.yaml': CFG}, RUN + ['--namespace', '/9rig'], 2,
     "--namespace: '/9rig' is not a ROS namespace"),
    ('rates differ', {'s.yaml': replaced('    sample_rate_hz: 1000.0\n    gain_source',
                                         '    sample_rate_hz: 500.0\n    gain_source')}, RUN, 2,
     'controller_node.ros__parameters.sample_rate_hz: 500 Hz differs from sim_node.ros__parameters.sample_rate_hz: '
     '1000 Hz'),
    ('domain -1', {'s.yaml': CFG}, RUN + ['--domain', '-1'], 2, '--domain: -1 is out of range; allowed 0..232'),
    ('domain 999', {'s.yaml': CFG}, RUN + ['--domain', '999'], 2, '--domain: 999 is out of range; allowed 0..232'),
    ('timeout -5', {'s.yaml': CFG}, RUN + ['--timeout', '-5'], 2, '--timeout: -5.0 must be > 0 wall seconds'),
    ('duration nan', {'s.yaml': CFG}, RUN + ['--duration', 'nan'], 2, '--duration: nan must be >= 0 s'),
    ('out is a file', {'s.yaml': CFG, 'out': b'my notes\n'}, RUN, 2, 'is a file; allowed: a directory'),
    ('out holds a bag', {'s.yaml': CFG, 'out/bag/metadata.yaml': b'x: 1\n'}, RUN, 2,
     'bag exists already; choose another --out'),
    ('bag is random bytes', {'b.mcap': bytes(range(256)) * 8}, ['analyze', '--no-plots', '{dir}/b.mcap'], 2,
     'not an MCAP file (it starts with'),
    ('bag is empty', {'b.mcap': b''}, ['analyze', '--no-plots', '{dir}/b.mcap'], 2, 'not an MCAP file (it is empty'),
    ('log of one row', {'b.csv': b't,x,voltage\n0,0,1\n'}, ['analyze', '--no-plots', '{dir}/b.csv'], 2,
     '1 samples is too short; at least 200 are needed'),
    ('bag is text', {'b.mcap': b't,x,voltage\n0,0,1\n'}, ['analyze', '--no-plots', '{dir}/b.mcap'], 2,
     'not an MCAP file'),
    *[(f'identify time limit {v}', {'b.csv': b't,x,voltage\n0,0,1\n'},
       ['identify', '{dir}/b.csv', '--out', '{dir}/id', '--time-limit', v], 2,
       f'--time-limit: {v} s; allowed a positive finite number of seconds') for v in ('0', '-5', 'nan', 'inf')],
]


def write(d: Path, files: dict) -> dict:
    for name, content in files.items():
        p = d / name
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(content if isinstance(content, bytes) else content.encode())
    return {p: p.read_bytes() for p in d.rglob('*') if p.is_file()}


@pytest.mark.parametrize('files, argv, code, phrase', [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_input_is_refused_by_name(tmp_path, capsys, files, argv, code, phrase):
    before = write(tmp_path, files)
    assert main([a.replace('{dir}', str(tmp_path)) for a in argv]) == code
    err = capsys.readouterr().err
    assert phrase in err, err
    assert {p: p.read_bytes() for p in tmp_path.rglob('*') if p.is_file()} == before   # nothing changed
    assert not list(tmp_path.rglob('logs'))                                             # nothing started


def test_a_domain_in_use_is_refused_before_start(tmp_path, capsys):
    domain = pick_domain()
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(('0.0.0.0', 7400 + 250 * domain + 10))   # what a participant of that domain holds
        write(tmp_path, {'s.yaml': CFG})
        assert main(['run', '--config', str(tmp_path / 's.yaml'), '--out', str(tmp_path / 'out'),
                     '--domain', str(domain)]) == 2
    assert f'--domain: ROS domain {domain} is in use by another process' in capsys.readouterr().err
    assert not (tmp_path / 'out').exists()


def test_an_exponent_without_a_dot_is_a_number_as_for_ros(tmp_path):
    (tmp_path / 's.yaml').write_text(replaced('theta0: 0.02', 'theta0: 2e-2'))
    assert load_scenario(tmp_path / 's.yaml').sim.theta0 == 0.02


def test_a_fifo_as_the_scenario_is_refused_as_not_a_file(tmp_path, capsys):
    import os
    os.mkfifo(tmp_path / 's.yaml')
    assert main([a.replace('{dir}', str(tmp_path)) for a in RUN]) == 2
    assert 's.yaml: not a regular file (a FIFO, device or directory); allowed: a YAML file' in capsys.readouterr().err
