"""Typed, validated parameters of the cart-pendulum and its friction (paper Tables 1-4).

Every field has a unit, a type and an allowed range; loading a YAML mapping that
violates any of them raises :class:`ConfigError` naming the field (dotted path),
the value and what is allowed.
"""
from __future__ import annotations

import math
import re
import stat
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import yaml

__all__ = ['FRICTION_MODELS', 'SMOOTHING', 'ConfigError', 'Field', 'check_number', 'check_choice', 'check_keys',
           'check_fields', 'PLANT_FIELDS', 'PlantParams', 'FRICTION_FIELDS', 'FrictionParams', 'load_yaml']

FRICTION_MODELS = ('viscous', 'coulomb', 'exponential', 'dynamic')
SMOOTHING = ('none', 'tanh')


class ConfigError(ValueError):
    """A configuration value is missing, of the wrong type or out of range."""


@dataclass(frozen=True)
class Field:
    """Schema of one numeric field: unit, open/closed range and description."""

    unit: str
    lo: float
    hi: float
    doc: str
    lo_open: bool = False
    integer: bool = False

    def describe(self) -> str:
        left = '(' if self.lo_open else '['
        return f'{left}{self.lo:g}, {self.hi:g}] {self.unit}'.rstrip()


def check_number(path: str, value: Any, spec: Field) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(f'{path}: expected a number in {spec.describe()} ({spec.doc}), '
                          f'got {type(value).__name__} {value!r}')
    if spec.integer and not isinstance(value, int):
        raise ConfigError(f'{path}: expected an integer in {spec.describe()} (written without a decimal point, '
                          f'as the ROS parameter is an integer), got {value!r}')
    v = float(value)
    if not math.isfinite(v):
        raise ConfigError(f'{path}: {value!r} is not finite; allowed {spec.describe()}')
    too_low = v <= spec.lo if spec.lo_open else v < spec.lo
    if too_low or v > spec.hi:
        raise ConfigError(f'{path}: {v:g} is out of range; allowed {spec.describe()} ({spec.doc})')
    return v


def check_choice(path: str, value: Any, allowed: tuple[str, ...]) -> str:
    """Return ``value`` if it is one of ``allowed``, else raise naming the field."""
    if not isinstance(value, str) or value not in allowed:
        raise ConfigError(f'{path}: {value!r} is not one of {", ".join(allowed)}')
    return value


def check_keys(path: str, data: Any, known: set[str], required: set[str]) -> Mapping:
    if not isinstance(data, Mapping):
        raise ConfigError(f'{path}: expected a mapping, got {type(data).__name__}')
    unknown = set(data) - known
    if unknown:
        raise ConfigError(f'{path}: unknown field(s) {", ".join(sorted(map(str, unknown)))}; '
                          f'allowed: {", ".join(sorted(known))}')
    missing = required - set(data)
    if missing:
        raise ConfigError(f'{path}: missing field(s) {", ".join(sorted(missing))}')
    return data


def check_fields(path: str, data: Any, fields: Mapping[str, Field], required=()) -> dict:
    """The numbers of mapping ``data`` checked against the schema ``fields`` (name -> Field): no unknown
    key, every ``required`` one present, each value in its range; integers as int."""
    data = check_keys(path, data, set(fields), set(required))
    return {k: (int if f.integer else float)(check_number(f'{path}.{k}', data[k], f))
            for k, f in fields.items() if k in data}


PLANT_FIELDS = {
    'M': Field('kg', 0.0, 1e3, 'cart mass', lo_open=True),
    'm': Field('kg', 0.0, 1e3, 'pendulum mass', lo_open=True),
    'l': Field('m', 0.0, 10.0, 'pivot to pendulum centre of mass', lo_open=True),
    'g': Field('m/s^2', 0.0, 100.0, 'gravity', lo_open=True),
    'alpha': Field('N/V', 0.0, 1e3, 'motor voltage-to-force factor, eq. (2)', lo_open=True),
    'beta': Field('N s/m', 0.0, 1e3, 'motor back-EMF damping, eq. (2)'),
}


@dataclass(frozen=True)
class PlantParams:
    """Cart-pendulum of paper Table 1 (SI units)."""

    M: float = 0.815
    m: float = 0.210
    l: float = 0.3050
    g: float = 9.8
    alpha: float = 1.7189
    beta: float = 7.682

    @classmethod
    def from_dict(cls, data: Any, path: str = 'plant') -> PlantParams:
        return cls(**check_fields(path, data, PLANT_FIELDS, PLANT_FIELDS))

    @property
    def normal_force(self) -> float:
        """F_N = (M + m) g [N], the paper's normal force with the pendulum attached."""
        return (self.M + self.m) * self.g


FRICTION_FIELDS = {
    'eps': Field('N s/m', 0.0, 1e3, 'viscous coefficient, eq. (3)/(7)'),
    'mu_s': Field('', 0.0, 2.0, 'static friction coefficient, eq. (5)'),
    'mu_c': Field('', 0.0, 2.0, 'Coulomb friction coefficient, eq. (6)'),
    'v_s': Field('m/s', 0.0, 10.0, 'Stribeck velocity, eq. (8)', lo_open=True),
    'gamma': Field('', 0.0, 10.0, 'Stribeck form factor, eq. (8)', lo_open=True),
    'sigma0': Field('N/m', 0.0, 1e9, 'bristle stiffness, eq. (10)', lo_open=True),
    'sigma1': Field('N s/m', 0.0, 1e6, 'bristle damping, eq. (11)'),
    'delta': Field('s/m', 0.0, 1e6, 'slope of the tanh(delta v) smoothing of sgn(v)', lo_open=True),
    'asymmetry': Field('', -0.9, 0.9, 'friction level (1 + a) forward, (1 - a) backward, static included'),
    'asymmetry_viscous': Field('N s/m', -1e3, 1e3, 'viscous term eps v + dF_v |v|: eps + dF_v forward, '
                               'eps - dF_v backward'),
}
# Fields each model needs (besides 'model' and 'smoothing').
FRICTION_REQUIRED = {
    'viscous': {'eps'},
    'coulomb': {'eps', 'mu_s', 'mu_c'},
    'exponential': {'eps', 'mu_s', 'mu_c', 'v_s', 'gamma'},
    'dynamic': {'eps', 'mu_s', 'mu_c', 'v_s', 'gamma', 'sigma0', 'sigma1'},
}


@dataclass(frozen=True)
class FrictionParams:
    """Cart-track friction: model name and coefficients (paper Tables 2-4, eq. 9).

    ``smoothing='tanh'`` replaces sgn(v) by tanh(delta v) (no sticking phase); with
    ``'none'`` the coulomb and exponential models stick exactly. ``delta`` is also
    the slope used to linearize a sticking model (paper section 3.1).
    """

    model: str = 'viscous'
    eps: float = 2.1
    mu_s: float = 0.0
    mu_c: float = 0.0
    v_s: float = 0.105
    gamma: float = 2.0
    sigma0: float = 121.0
    sigma1: float = 70.0
    smoothing: str = 'none'
    delta: float = 100.0
    asymmetry: float = 0.0
    asymmetry_viscous: float = 0.0

    @classmethod
    def from_dict(cls, data: Any, path: str = 'friction') -> FrictionParams:
        if not isinstance(data, Mapping):
            raise ConfigError(f'{path}: expected a mapping, got {type(data).__name__}')
        model = check_choice(f'{path}.model', data.get('model'), FRICTION_MODELS)
        known = set(FRICTION_FIELDS) | {'model', 'smoothing'}
        check_keys(path, data, known, FRICTION_REQUIRED[model] | {'model'})
        values = {k: check_number(f'{path}.{k}', data[k], s)
                  for k, s in FRICTION_FIELDS.items() if k in data}
        smoothing = check_choice(f'{path}.smoothing', data.get('smoothing', 'none'), SMOOTHING)
        if smoothing == 'tanh' and model not in ('coulomb', 'exponential'):
            raise ConfigError(f'{path}.smoothing: tanh applies to the coulomb and exponential '
                              f'models, not {model!r}; use none')
        if model == 'coulomb' and values.get('mu_c', 0.0) > values.get('mu_s', 0.0):
            raise ConfigError(f'{path}.mu_c: {values["mu_c"]:g} exceeds mu_s = {values["mu_s"]:g}; allowed '
                              f'0 <= mu_c <= mu_s for the coulomb law (a static level below the Coulomb level '
                              f'needs the Stribeck curve of the exponential or dynamic law to rise to it)')
        return cls(model=model, smoothing=smoothing, **values)

    def to_dict(self) -> dict:
        """Only the fields the model uses, in YAML-ready form."""
        keep = FRICTION_REQUIRED[self.model] | {'model'}
        if self.model in ('coulomb', 'exponential'):
            keep |= {'smoothing', 'delta'}
        keep |= {k for k in ('asymmetry', 'asymmetry_viscous') if getattr(self, k)}
        return {k: v for k, v in asdict(self).items() if k in keep}

    def replace(self, **changes) -> FrictionParams:
        data = asdict(self)
        data.update(changes)
        return FrictionParams(**data)


class _Loader(yaml.SafeLoader):
    """YAML as the ROS 2 parameter parser reads it: ``2e-2`` is a float (YAML 1.2), and a
    key given twice in one mapping is refused (PyYAML would keep the last one silently)."""

    def construct_mapping(self, node, deep=False):
        seen = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            line = key_node.start_mark.line + 1
            if key in seen:
                raise ConfigError(f'{self.name}: key {key!r} given twice, on lines {seen[key]} and {line} '
                                  f'(keep one)')
            seen[key] = line
        return super().construct_mapping(node, deep)


_Loader.yaml_implicit_resolvers = {k: list(v) for k, v in yaml.SafeLoader.yaml_implicit_resolvers.items()}
_Loader.add_implicit_resolver('tag:yaml.org,2002:float',
                              re.compile(r'^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$'),
                              list('-+0123456789'))


def load_yaml(path: str | Path) -> Any:
    """Parse a YAML file (UTF-8), turning every problem into ConfigError with the location."""
    path = Path(path)
    try:
        if not stat.S_ISREG(path.stat().st_mode):
            raise ConfigError(f'{path}: not a regular file (a FIFO, device or directory); allowed: a YAML file')
        raw = path.read_bytes()
    except OSError as exc:
        raise ConfigError(f'{path}: cannot read ({exc.strerror})') from exc
    try:
        text = raw.decode('utf-8')
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b'\n') + 1
        raise ConfigError(f'{path}: line {line}: byte {raw[exc.start]:#04x} is not UTF-8 text; save the file '
                          f'as UTF-8') from exc
    loader = _Loader(text)
    loader.name = str(path)
    try:
        data = loader.get_single_data()
    except yaml.YAMLError as exc:
        mark = getattr(exc, 'problem_mark', None)
        where = f' line {mark.line + 1} column {mark.column + 1}' if mark else ''
        raise ConfigError(f'{path}:{where} malformed YAML: {getattr(exc, "problem", exc)}') from exc
    finally:
        loader.dispose()
    if not isinstance(data, Mapping):
        raise ConfigError(f'{path}: expected a mapping at top level, got {type(data).__name__}')
    return data
