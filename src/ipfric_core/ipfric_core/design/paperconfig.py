"""The paper's parameter file (``config/paper.yaml``): plant, named friction models, LQR weights."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..constants import REPO_ROOT
from ..physics.params import ConfigError, FrictionParams, PlantParams, check_keys, check_number, load_yaml
from .lqr import CONTROL_WEIGHT, STATE_WEIGHT

__all__ = ['DEFAULT_CONFIG', 'DEFAULT_DATA', 'PaperConfig', 'load_paper_config']

DEFAULT_CONFIG = REPO_ROOT / 'config' / 'paper.yaml'
DEFAULT_DATA = REPO_ROOT.parent / 'shared' / 'data'


@dataclass(frozen=True)
class PaperConfig:
    plant: PlantParams
    friction: dict[str, FrictionParams]
    Q: tuple[float, ...]
    R: float


def load_paper_config(path: str | Path = DEFAULT_CONFIG) -> PaperConfig:
    """Load and validate ``config/paper.yaml``; errors name the offending field."""
    data = load_yaml(path)
    check_keys(str(path), data, {'plant', 'friction', 'design'}, {'plant', 'friction', 'design'})
    plant = PlantParams.from_dict(data['plant'])
    fr = data['friction']
    if not isinstance(fr, dict) or not fr:
        raise ConfigError('friction: expected a mapping of named friction models')
    friction = {str(k): FrictionParams.from_dict(v, f'friction.{k}') for k, v in fr.items()}
    for needed in ('viscous', 'exponential', 'dynamic'):
        if needed not in friction:
            raise ConfigError(f'friction.{needed}: missing; the paper report needs viscous, '
                              f'exponential and dynamic')
    des = check_keys('design', data['design'], {'Q', 'R'}, {'Q', 'R'})
    Q = des['Q']
    if not isinstance(Q, list) or len(Q) != 4:
        raise ConfigError(f'design.Q: expected 4 weights on (x, theta, x\', theta\'), got {Q!r}')
    Q = tuple(check_number(f'design.Q[{i}]', q, STATE_WEIGHT) for i, q in enumerate(Q))
    R = check_number('design.R', des['R'], CONTROL_WEIGHT)
    return PaperConfig(plant, friction, Q, R)
