"""The cart-pendulum URDF (ipfric_bringup/urdf): what robot_state_publisher needs to turn the rig's
joint_states into TF, and the geometry of the model (no ROS needed)."""
import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from ipfric_core.constants import JOINT_NAMES, REPO_ROOT, TRACK_LIMIT_M
from ipfric_core.physics.params import PlantParams

URDF = REPO_ROOT / 'src' / 'ipfric_bringup' / 'urdf' / 'cart_pendulum.urdf'


@pytest.fixture(scope='module')
def robot():
    return ET.parse(URDF).getroot()


def test_the_moving_joints_are_the_joint_states_names(robot):
    moving = {j.get('name'): j for j in robot.iter('joint') if j.get('type') != 'fixed'}
    assert tuple(moving) == JOINT_NAMES
    assert moving['cart'].get('type') == 'prismatic' and moving['cart'].find('axis').get('xyz') == '1 0 0'
    limit = moving['cart'].find('limit')
    assert float(limit.get('lower')) == -TRACK_LIMIT_M and float(limit.get('upper')) == TRACK_LIMIT_M
    assert moving['pendulum'].get('type') == 'continuous' and moving['pendulum'].find('axis').get('xyz') == '0 1 0'


def test_one_tree_from_world(robot):
    links = {link.get('name') for link in robot.iter('link')}
    children = [j.find('child').get('link') for j in robot.iter('joint')]
    parents = [j.find('parent').get('link') for j in robot.iter('joint')]
    assert len(children) == len(set(children)) and set(children) | {'world'} == links
    assert set(parents) <= links and 'world' not in children


def tip(robot, x: float, theta: float) -> np.ndarray:
    """The rod's far end in the world frame for joint values (x, theta), through the URDF's origins and axes."""
    joints = {j.find('child').get('link'): j for j in robot.iter('joint')}
    rod = float(next(link for link in robot.iter('link') if link.get('name') == 'pendulum_link')
                .find('visual/geometry/cylinder').get('length'))
    chain, link = [], 'pendulum_link'
    while link in joints:
        chain.append(joints[link])
        link = joints[link].find('parent').get('link')
    p, R = np.zeros(3), np.eye(3)
    for j in reversed(chain):
        p = p + R @ np.array([float(v) for v in j.find('origin').get('xyz').split()])
        axis = np.array([float(v) for v in (j.find('axis').get('xyz') if j.find('axis') is not None else '0 0 0')
                         .split()])
        if j.get('type') == 'prismatic':
            p = p + R @ axis * x
        elif j.get('type') == 'continuous':
            c, s = math.cos(theta), math.sin(theta)       # rotation about y (the axis checked above)
            R = R @ np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return p + R @ np.array([0.0, 0.0, rod])


def test_the_rod_is_the_papers_pendulum_and_leans_as_theta(robot):
    """Length 2 l (l: pivot to centre of mass, Table 1); upright at theta = 0; a positive theta puts
    the tip towards +x, the sign of the plant's equation (1) (a cart accelerating to +x drives theta down)."""
    l = PlantParams().l
    up, right = tip(robot, 0.0, 0.0), tip(robot, 0.1, 0.3)
    base = tip(robot, 0.0, math.pi / 2)
    assert up[0] == pytest.approx(base[0] - 2 * l) and up[2] - base[2] == pytest.approx(2 * l)
    assert right[0] - up[0] == pytest.approx(0.1 + 2 * l * math.sin(0.3))
    assert right[2] - up[2] == pytest.approx(2 * l * (math.cos(0.3) - 1))
