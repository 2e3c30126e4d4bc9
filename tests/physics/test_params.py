import pytest

from ipfric_core.design.paperconfig import load_paper_config
from ipfric_core.physics.params import ConfigError, FrictionParams, PlantParams

GOOD_PLANT = dict(M=0.815, m=0.21, l=0.305, g=9.8, alpha=1.7189, beta=7.682)


def test_paper_config_loads_tables(paper_cfg):
    assert paper_cfg.plant.M == 0.815 and paper_cfg.plant.alpha == 1.7189
    assert paper_cfg.friction['exponential'].mu_s == 0.0861
    assert paper_cfg.friction['dynamic'].sigma0 == 121.0
    assert paper_cfg.Q == (5000.0, 3000.0, 20.0, 20.0)


@pytest.mark.parametrize('change, words', [
    ({'M': -1.0}, ['plant.M', 'out of range', '(0, 1000] kg']),
    ({'alpha': 'big'}, ['plant.alpha', 'expected a number', 'str']),
    ({'beta': float('nan')}, ['plant.beta', 'not finite']),
    ({'mass': 1.0}, ['unknown field', 'mass']),
])
def test_bad_plant_values_name_the_field(change, words):
    data = dict(GOOD_PLANT, **change)
    with pytest.raises(ConfigError) as exc:
        PlantParams.from_dict(data)
    for w in words:
        assert w in str(exc.value)


def test_missing_plant_field():
    data = dict(GOOD_PLANT)
    del data['l']
    with pytest.raises(ConfigError, match=r'plant: missing field\(s\) l'):
        PlantParams.from_dict(data)


def test_unknown_friction_model_lists_allowed():
    with pytest.raises(ConfigError) as exc:
        FrictionParams.from_dict({'model': 'lugre', 'eps': 1.0})
    assert "friction.model: 'lugre' is not one of viscous, coulomb, exponential, dynamic" in str(exc.value)


def test_friction_model_needs_its_fields():
    with pytest.raises(ConfigError, match=r'friction: missing field\(s\) gamma, v_s'):
        FrictionParams.from_dict({'model': 'exponential', 'eps': 3, 'mu_s': 0.08, 'mu_c': 0.04})


def test_coulomb_above_static_is_refused():
    with pytest.raises(ConfigError, match='friction.mu_c: 0.09 exceeds mu_s = 0.08; allowed 0 <= mu_c <= mu_s for '
                                          'the coulomb law'):
        FrictionParams.from_dict({'model': 'coulomb', 'eps': 3, 'mu_s': 0.08, 'mu_c': 0.09})


def test_smoothing_choice_checked():
    with pytest.raises(ConfigError, match="friction.smoothing: 'sigmoid' is not one of none, tanh"):
        FrictionParams.from_dict({'model': 'coulomb', 'eps': 3, 'mu_s': 0.08, 'mu_c': 0.04,
                                  'smoothing': 'sigmoid'})


def test_malformed_yaml_reports_line(tmp_path):
    p = tmp_path / 'bad.yaml'
    p.write_text('plant:\n  M: [0.8\n  m: 0.2\n')
    with pytest.raises(ConfigError, match='line 3.*malformed YAML'):
        load_paper_config(p)


def test_round_trip_to_dict():
    f = FrictionParams.from_dict({'model': 'exponential', 'eps': 3, 'mu_s': 0.0861, 'mu_c': 0.04287,
                                  'v_s': 0.105, 'gamma': 2})
    assert FrictionParams.from_dict(f.to_dict()) == f
