"""The PlotJuggler layout plots only series an ipfric bag holds (topic and message field)."""
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LAYOUT = ROOT / 'src' / 'ipfric_bringup' / 'plotjuggler' / 'ipfric_run.xml'
MSGS = ROOT / 'src' / 'ipfric_msgs' / 'msg'
# topic -> (fields of its message, joint names for sensor_msgs/JointState)
TOPICS = {'/joint_states': ({'position', 'velocity', 'effort'}, ('cart', 'pendulum')),
          '/plant_state': ('PlantState', None), '/voltage_command': ('VoltageCommand', None),
          '/safety_event': ('SafetyEvent', None)}


def fields(msg: str) -> set:
    lines = [ln.split('#')[0].split() for ln in (MSGS / f'{msg}.msg').read_text().splitlines()]
    return {w[1] for w in lines if len(w) == 2}           # "type name" (constants have "=")


def test_every_curve_is_a_recorded_series():
    root = ET.parse(LAYOUT).getroot()
    areas = root.findall('.//DockArea')
    assert [a.get('name').split(' ')[0] for a in areas] == ['cart', 'pendulum', 'command', 'safety']
    curves = [c.get('name') for c in root.iter('curve')]
    assert '/safety_event/sample_index' in curves and '/voltage_command/voltage' in curves
    for name in curves:
        topic = '/' + name.split('/')[1]
        spec, joints = TOPICS[topic]
        if joints:
            _, _, joint, field = name.split('/')
            assert joint in joints and field in spec, name
        else:
            assert name.split('/')[2] in fields(spec), name
