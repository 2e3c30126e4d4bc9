"""The true rig's undeclared effects and the scenario file validation."""
import math

import pytest

from ipfric_core.physics.params import ConfigError, FrictionParams, PlantParams
from ipfric_core.physics.plant import CartPendulum, drive_contact_force
from ipfric_core.physics.rig import PlantTruth, Rig, apply_input_effects, play
from ipfric_core.run.scenario import Scenario, load_scenario, nest, scenario_from_ros_params

EXP = FrictionParams('exponential', eps=3.0, mu_s=0.0861, mu_c=0.04287, v_s=0.105, gamma=2.0)
SIM = {'plant': {'M': 0.815, 'm': 0.21, 'l': 0.305, 'g': 9.8, 'alpha': 1.7189, 'beta': 7.682},
       'friction': EXP.to_dict()}
CTRL = {'gain': [70.7107, 142.5409, 50.6911, 26.9817]}


def rig(truth, theta0=math.pi, res=(0.0, 0.0)):
    return Rig(CartPendulum(PlantParams(), EXP), truth, [0.0, theta0, 0.0, 0.0], 1e-3, res,
               fallen_angle=4.0)


def test_deadzone_and_saturation():
    t = PlantTruth(deadzone_V=0.5, saturation_V=2.0)
    assert apply_input_effects(0.3, t) == 0.0
    assert apply_input_effects(-1.0, t) == pytest.approx(-0.5)
    assert apply_input_effects(9.0, t) == 2.0


def test_input_delay_shifts_the_applied_voltage():
    r = rig(PlantTruth(input_delay_s=0.003))
    applied = []
    for v in (1.0, 2.0, 3.0, 4.0, 5.0):
        r.step(v)
        applied.append(r.voltage_applied)
    assert applied == [0.0, 0.0, 0.0, 1.0, 2.0]


def test_cogging_force_moves_a_resting_cart():
    """0.95 N of cogging at x = P/4 exceeds mu_s F_N = 0.865 N: the cart breaks away unpowered."""
    r = Rig(CartPendulum(PlantParams(), EXP), PlantTruth(cogging_sin_N=0.95, cogging_period_m=0.02),
            [0.005, math.pi, 0.0, 0.0], 1e-3, fallen_angle=4.0)
    for _ in range(50):
        r.step(0.0)
    assert r.truth()['x'] > 0.005
    still = rig(PlantTruth(cogging_sin_N=0.5, cogging_period_m=0.02))
    for _ in range(50):
        still.step(0.0)
    assert still.truth()['x'] == 0.0 and still.truth()['stuck']


def test_asymmetry_brakes_forward_motion_more():
    ends = {}
    for a in (0.0, 0.2):
        r = rig(PlantTruth(asymmetry=a))
        for _ in range(300):
            r.step(2.0)
        ends[a] = r.truth()['x']
    assert ends[0.2] < ends[0.0] - 1e-3


def test_backlash_play_and_sensor_bias_noise():
    assert play(0.0, 0.0004, 0.001) == 0.0
    assert play(0.0, 0.0015, 0.001) == pytest.approx(0.001)
    r = rig(PlantTruth(bias_theta_rad=0.01, bias_x_m=0.002), theta0=0.0)
    assert r.measure() == pytest.approx((0.002, 0.01))
    a = rig(PlantTruth(noise_theta_rad=1e-3, noise_seed=7), theta0=0.0)
    b = rig(PlantTruth(noise_theta_rad=1e-3, noise_seed=7), theta0=0.0)
    assert [a.measure() for _ in range(3)] == [b.measure() for _ in range(3)]


def test_drive_play_keeps_the_motor_force_off_the_cart_until_the_motor_side_crosses_it():
    """1 V (1.72 N, twice the breakaway force) through a 1 mm play: the motor side (0.2 kg, speed
    tending to alpha V / beta = 0.224 m/s with time constant 0.2 / 7.682 = 26 ms) starts in the
    middle and crosses half the play in about sqrt(2 * 0.026 s * 0.5 mm / 0.224 m/s) = 11 ms;
    until then nothing reaches the cart (held with no force). Then the cart moves, behind a
    rigid drive (its knock and the motor side's inertia)."""
    truth = PlantTruth(drive_backlash_m=1e-3, drive_mass_kg=0.2, drive_stiffness_N_per_m=2e5,
                       drive_damping_Ns_per_m=50.0)
    r, rigid = rig(truth), rig(PlantTruth())
    for _ in range(10):
        r.step(1.0)
        rigid.step(1.0)
    assert r.truth()['x'] == 0.0 and r.truth()['stuck'] and abs(r.truth()['friction_force']) < 1e-9
    assert rigid.truth()['x'] > 4e-5
    for _ in range(50):
        r.step(1.0)
        rigid.step(1.0)
    assert 0.9 * rigid.truth()['x'] < r.truth()['x'] < rigid.truth()['x'] - 2e-5


def test_drive_contact_pushes_beyond_the_play_and_never_pulls():
    dp = (1e-3, 0.2, 2e5, 50.0)
    assert drive_contact_force(dp, 4e-4, 1.0) == 0.0                           # inside the play
    assert drive_contact_force(dp, 6e-4, 0.01) == pytest.approx(2e5 * 1e-4 + 0.5)
    assert drive_contact_force(dp, -6e-4, -0.01) == pytest.approx(-(2e5 * 1e-4 + 0.5))
    assert drive_contact_force(dp, 6e-4, -1.0) == 0.0                          # leaving fast: no pull


def test_a_drive_play_needs_its_motor_side_and_contact():
    bad = dict(SIM, plant_truth={'drive_backlash_m': 1e-3, 'drive_stiffness_N_per_m': 2e5})
    with pytest.raises(ConfigError, match='plant_truth.drive_mass_kg'):
        scenario_from_ros_params(bad, CTRL)


def test_encoder_quantization_in_the_rig():
    r = rig(PlantTruth(), theta0=0.0123, res=(1e-4, math.radians(0.08789)))
    x, th = r.measure()
    assert th == pytest.approx(math.radians(0.08789) * 8)


def test_scenario_round_trip_and_design_source():
    s = scenario_from_ros_params(SIM, {'gain_source': 'design', 'design_friction': {'model': 'viscous', 'eps': 2.1}})
    assert s.gain() == pytest.approx([70.7107, 142.5409, 50.6911, 26.9817], rel=1e-5)
    d = s.to_dict()
    assert d['friction']['model'] == 'exponential' and d['controller']['gain_source'] == 'design'


@pytest.mark.parametrize('sim, ctrl, words', [
    ({**SIM, 'time_mode': 'fast'}, CTRL, "time_mode: 'fast' is not one of lockstep, realtime"),
    ({**SIM, 'friction': {'model': 'magic'}}, CTRL, "friction.model: 'magic' is not one of viscous"),
    ({**SIM, 'plant_truth': {'cogging': 1.0}}, CTRL, 'plant_truth: unknown field(s) cogging'),
    ({**SIM, 'plant_truth': {'input_delay_s': 0.0015}}, CTRL, 'input_delay_s'),
    (SIM, {'gain': [1, 2, 3]}, 'gain: expected 4 finite numbers'),
    (SIM, {'gain': [1, 2, 3, 4, 5]}, 'gain: entry 4 (the bristle state z) must be 0'),
    (SIM, {'gain': [1, 2, 3, float('inf')]}, 'gain: expected 4 finite numbers'),
    (SIM, {**CTRL, 'delay': 0.0105}, 'delay: delay tau = 0.0105 s is not a multiple'),
    (SIM, {'gain_source': 'design'}, 'design_friction: missing'),
])
def test_scenario_errors_name_the_field(sim, ctrl, words):
    with pytest.raises(ConfigError) as exc:
        scenario_from_ros_params(sim, ctrl)
    assert words in str(exc.value)


def test_scenario_file_sections(tmp_path):
    p = tmp_path / 's.yaml'
    p.write_text('sim_node:\n  ros__parameters: {}\n')
    with pytest.raises(ConfigError, match='no section for controller_node'):
        load_scenario(p)


def test_flat_ros_parameters_nest_back():
    flat = Scenario.flat_defaults('sim_node')
    nested = nest({k: v[0] for k, v in flat.items()})
    nested['friction'] = EXP.to_dict() | {k: nested['friction'][k] for k in ('sigma0', 'sigma1')}
    s = scenario_from_ros_params(nested, CTRL)
    assert s.sim.sample_rate_hz == 1000.0 and s.truth == PlantTruth()
    assert all(isinstance(v[1], str) and v[1] for v in flat.values())
