"""A run scenario: one ROS 2 parameter file for the simulator and controller nodes.

The file is an ordinary ``--params-file`` YAML, its sections keyed in the ROS wildcard form
that matches the nodes in any namespace (``/**/sim_node``; rcl's rules, :func:`key_matches`)::

    /**/sim_node:
      ros__parameters:
        sample_rate_hz: 1000.0   # [Hz]
        duration: 20.0           # [s], 0 = until stopped
        time_mode: lockstep      # lockstep | realtime
        lockstep_timeout_s: 1.0  # [s] wall time to wait for a command
        watchdog_samples: 50     # samples without a valid command -> V = 0
        voltage_max: 10.0        # [V] commands beyond it are refused
        theta0: 0.02             # [rad] initial angle, history of eq. (30)
        track_limit: 0.4         # [m]
        fallen_angle: 0.5236     # [rad]
        cart_resolution: 4.54e-05    # [m] encoder count
        angle_resolution: 0.0015340  # [rad] encoder count
        plant: {M: ..., m: ..., l: ..., g: ..., alpha: ..., beta: ...}
        friction: {model: exponential, eps: ..., ...}
        plant_truth: {cogging_N: 0.0, ...}           # undeclared effects, rig.PlantTruth
    /**/controller_node:
      ros__parameters:
        sample_rate_hz: 1000.0
        gain_source: yaml        # yaml | design
        gain: [70.7107, 142.5409, 50.6911, 26.9817]
        delay: 0.0               # [s] artificial feedback delay tau, eq. (26)
        cutoff_hz: 20.0          # [Hz] velocity filter
        voltage_limit: 10.0      # [V]
        plant: {...}             # used when gain_source = design
        design_friction: {...}
        Q: [5000.0, 3000.0, 20.0, 20.0]
        R: 1.0

The same validation serves the offline tools and the nodes (which pass their own
parameters, nested again, to :func:`scenario_from_ros_params`).
"""
from __future__ import annotations

import difflib
import math
import os
import re
from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

from ..constants import ANGLE_RESOLUTION_RAD, CART_RESOLUTION_M, FALLEN_ANGLE_RAD, REPO_ROOT, TRACK_LIMIT_M
from ..design.lqr import CONTROL_WEIGHT, STATE_WEIGHT, design
from ..physics.controller import StateFeedback, delay_samples, gain_vector
from ..physics.params import (
    FRICTION_FIELDS,
    FRICTION_MODELS,
    PLANT_FIELDS,
    SMOOTHING,
    ConfigError,
    Field,
    FrictionParams,
    PlantParams,
    check_choice,
    check_fields,
    check_keys,
    check_number,
    load_yaml,
)
from ..physics.plant import CartPendulum
from ..physics.rig import PLANT_TRUTH_FIELDS, PlantTruth, Rig

__all__ = ['DEFAULT_SCENARIO', 'TIME_MODES', 'NODE_NAMES', 'SECTION_KEYS', 'SIM_FIELDS', 'CONTROLLER_FIELDS',
           'Scenario', 'check_namespace', 'key_matches', 'nest', 'section_node', 'node_sections',
           'scenario_from_ros_params', 'scenario_from_sections', 'load_scenario', 'scenario_path']

#: the scenario ``./ipfric run`` and the other commands take when none is given
DEFAULT_SCENARIO = REPO_ROOT / 'config' / 'default.yaml'
TIME_MODES = ('lockstep', 'realtime')
GAIN_SOURCES = ('yaml', 'design')

SIM_FIELDS = {
    'sample_rate_hz': Field('Hz', 1.0, 1e5, 'sample rate of encoders and commands'),
    'duration': Field('s', 0.0, 1e6, 'simulated run length, 0 = until stopped'),
    'lockstep_timeout_s': Field('s', 0.0, 60.0, 'lockstep: wall time to wait for a command', lo_open=True),
    'watchdog_samples': Field('samples', 1, 1e6, 'samples without a valid command before V = 0', integer=True),
    'voltage_max': Field('V', 0.0, 1e3, 'largest accepted command', lo_open=True),
    'theta0': Field('rad', -1.0, 1.0, 'initial angle from upright, eq. (30)'),
    'track_limit': Field('m', 0.0, 10.0, 'end the run beyond |x|', lo_open=True),
    'fallen_angle': Field('rad', 0.0, math.pi, 'end the run beyond |theta|', lo_open=True),
    'cart_resolution': Field('m', 0.0, 1.0, 'cart encoder count (0 = exact)'),
    'angle_resolution': Field('rad', 0.0, 1.0, 'angle encoder count (0 = exact)'),
}
CONTROLLER_FIELDS = {
    'sample_rate_hz': SIM_FIELDS['sample_rate_hz'],
    'delay': Field('s', 0.0, 10.0, 'artificial feedback delay tau, eq. (26), a multiple of the sample period'),
    'cutoff_hz': Field('Hz', 0.0, 1e4, 'velocity filter corner (0 = raw difference)'),
    'voltage_limit': Field('V', 0.0, 1e3, 'command saturation', lo_open=True),
    'R': CONTROL_WEIGHT,
}
DEFAULT_Q = [5000.0, 3000.0, 20.0, 20.0]
GAIN = Field('V per SI unit', -1e6, 1e6, 'state feedback gain')


@dataclass(frozen=True)
class SimSettings:
    sample_rate_hz: float = 1000.0
    duration: float = 20.0
    time_mode: str = 'lockstep'
    lockstep_timeout_s: float = 1.0
    watchdog_samples: int = 50
    voltage_max: float = 10.0
    theta0: float = 0.02
    track_limit: float = TRACK_LIMIT_M
    fallen_angle: float = FALLEN_ANGLE_RAD
    cart_resolution: float = CART_RESOLUTION_M
    angle_resolution: float = ANGLE_RESOLUTION_RAD


@dataclass(frozen=True)
class ControllerSettings:
    sample_rate_hz: float = 1000.0
    gain_source: str = 'yaml'
    gain: tuple | None = None
    delay: float = 0.0
    cutoff_hz: float = 20.0
    voltage_limit: float = 10.0
    plant: PlantParams = PlantParams()
    design_friction: FrictionParams | None = None
    Q: tuple = tuple(DEFAULT_Q)
    R: float = 1.0


def _gain(path: str, value: Any) -> tuple:
    try:
        gain = gain_vector(value if isinstance(value, (list, tuple)) else [value])
    except ValueError as exc:
        raise ConfigError(f'{path}: {exc}') from None
    return tuple(check_number(f'{path}[{i}]', v, GAIN) for i, v in enumerate(gain))


def parse_sim(data: Mapping, path: str = 'sim_node.ros__parameters'):
    """(SimSettings, PlantParams, FrictionParams, PlantTruth) from a nested mapping."""
    known = set(SIM_FIELDS) | {'time_mode', 'plant', 'friction', 'plant_truth', 'use_sim_time'}
    data = check_keys(path, data, known, {'plant', 'friction'})
    values: dict[str, Any] = check_fields(path, {k: v for k, v in data.items() if k in SIM_FIELDS}, SIM_FIELDS)
    values['time_mode'] = check_choice(f'{path}.time_mode', data.get('time_mode', 'lockstep'), TIME_MODES)
    sim = SimSettings(**values)
    plant = PlantParams.from_dict(data['plant'], f'{path}.plant')
    friction = FrictionParams.from_dict(data['friction'], f'{path}.friction')
    truth = PlantTruth.from_dict(data.get('plant_truth', {}) or {}, f'{path}.plant_truth')
    dt = 1.0 / sim.sample_rate_hz
    try:
        delay_samples(truth.input_delay_s, dt)
    except ValueError as exc:
        raise ConfigError(f'{path}.plant_truth.input_delay_s: {exc}') from exc
    if truth.drive_backlash_m > 0.0:
        for k in ('drive_mass_kg', 'drive_stiffness_N_per_m'):
            if getattr(truth, k) <= 0.0:
                raise ConfigError(f'{path}.plant_truth.{k}: must be > 0 with a drive_backlash_m '
                                  f'({PLANT_TRUTH_FIELDS[k].unit}), got {getattr(truth, k)}')
    return sim, plant, friction, truth


def parse_controller(data: Mapping, path: str = 'controller_node.ros__parameters') -> ControllerSettings:
    known = set(CONTROLLER_FIELDS) | {'gain_source', 'gain', 'plant', 'design_friction', 'Q', 'use_sim_time'}
    data = check_keys(path, data, known, set())
    values: dict[str, Any] = check_fields(path, {k: v for k, v in data.items() if k in CONTROLLER_FIELDS},
                                          CONTROLLER_FIELDS)
    source = check_choice(f'{path}.gain_source', data.get('gain_source', 'yaml'), GAIN_SOURCES)
    gain = design_friction = None
    plant = PlantParams.from_dict(data['plant'], f'{path}.plant') if 'plant' in data else PlantParams()
    if source == 'yaml':
        if 'gain' not in data:
            raise ConfigError(f'{path}.gain: missing; gain_source yaml needs 4 gains')
        gain = _gain(f'{path}.gain', data['gain'])
    else:
        if 'design_friction' not in data:
            raise ConfigError(f'{path}.design_friction: missing; gain_source design needs a friction model '
                              f'({", ".join(FRICTION_MODELS)})')
        design_friction = FrictionParams.from_dict(data['design_friction'], f'{path}.design_friction')
    Q = data.get('Q', DEFAULT_Q)
    if not isinstance(Q, (list, tuple)) or len(Q) != 4:
        raise ConfigError(f'{path}.Q: expected 4 weights on (x, theta, x\', theta\'), got {Q!r}')
    Q = tuple(check_number(f'{path}.Q[{i}]', q, STATE_WEIGHT) for i, q in enumerate(Q))
    settings = ControllerSettings(gain_source=source, gain=gain, plant=plant, design_friction=design_friction,
                                  Q=Q, **values)
    try:
        delay_samples(settings.delay, 1.0 / settings.sample_rate_hz)
    except ValueError as exc:
        raise ConfigError(f'{path}.delay: {exc}') from exc
    return settings


@dataclass(frozen=True)
class Scenario:
    sim: SimSettings
    plant: PlantParams
    friction: FrictionParams
    truth: PlantTruth
    controller: ControllerSettings

    @property
    def sample_period(self) -> float:
        return 1.0 / self.sim.sample_rate_hz

    def gain(self) -> list:
        """The gain the controller applies: from YAML, or designed on ``design_friction``."""
        c = self.controller
        if c.gain is not None:
            return list(c.gain)
        assert c.design_friction is not None  # parse_controller requires it without a gain
        return design(c.plant, c.design_friction, c.Q, c.R).gain[:4].tolist()

    def make_rig(self) -> Rig:
        s = self.sim
        return Rig(CartPendulum(self.plant, self.friction), self.truth, [0.0, s.theta0, 0.0, 0.0],
                   self.sample_period, (s.cart_resolution, s.angle_resolution), s.track_limit, s.fallen_angle)

    def make_controller(self) -> StateFeedback:
        c = self.controller
        return StateFeedback(self.gain(), 1.0 / c.sample_rate_hz, c.delay, c.cutoff_hz, c.voltage_limit)

    def to_dict(self) -> dict:
        """The full configuration, JSON/YAML-ready, with the gain actually used."""
        c = self.controller
        ctrl = {k: v for k, v in asdict(c).items() if k not in ('plant', 'design_friction', 'gain', 'Q')}
        ctrl.update(gain=list(c.gain) if c.gain else None, Q=list(c.Q),
                    plant=asdict(c.plant),
                    design_friction=c.design_friction.to_dict() if c.design_friction else None)
        return {'sim': asdict(self.sim), 'plant': asdict(self.plant), 'friction': self.friction.to_dict(),
                'plant_truth': self.truth.to_dict(), 'controller': ctrl, 'gain': self.gain()}

    def to_ros_params(self) -> dict:
        """The scenario as a ``--params-file`` mapping (inverse of :func:`load_scenario`)."""
        c = self.controller
        sim = {**asdict(self.sim), 'plant': asdict(self.plant), 'friction': self.friction.to_dict(),
               'plant_truth': self.truth.to_dict()}
        ctrl = {'use_sim_time': True, 'sample_rate_hz': c.sample_rate_hz, 'gain_source': c.gain_source,
                'delay': c.delay,
                'cutoff_hz': c.cutoff_hz, 'voltage_limit': c.voltage_limit, 'plant': asdict(c.plant),
                'Q': list(c.Q), 'R': c.R}
        if c.gain is not None:
            ctrl['gain'] = list(c.gain)
        if c.design_friction is not None:
            ctrl['design_friction'] = c.design_friction.to_dict()
        return {SECTION_KEYS['sim_node']: {'ros__parameters': sim},
                SECTION_KEYS['controller_node']: {'ros__parameters': ctrl}}

    @staticmethod
    def flat_defaults(node: str) -> dict:
        """Every ROS parameter of ``node`` as name -> (default, description, (lo, hi) or None)."""
        out: dict = {}

        def num(name, default, spec: Field):
            out[name] = (default, f'{spec.doc} [{spec.unit}]' if spec.unit else spec.doc, (spec.lo, spec.hi))

        def friction(prefix, fp: FrictionParams):
            out[f'{prefix}.model'] = (fp.model, 'friction model: ' + ' | '.join(FRICTION_MODELS), None)
            out[f'{prefix}.smoothing'] = (fp.smoothing, 'sgn(v) smoothing: ' + ' | '.join(SMOOTHING), None)
            for k, spec in FRICTION_FIELDS.items():
                num(f'{prefix}.{k}', getattr(fp, k), spec)

        def plant(prefix):
            for k, spec in PLANT_FIELDS.items():
                num(f'{prefix}.{k}', getattr(PlantParams(), k), spec)

        if node == 'sim_node':
            for k, spec in SIM_FIELDS.items():
                num(k, getattr(SimSettings(), k), spec)
            out['time_mode'] = ('lockstep', 'lockstep | realtime', None)
            plant('plant')
            friction('friction', FrictionParams())
            for f in fields(PlantTruth):
                num(f'plant_truth.{f.name}', f.default, PLANT_TRUTH_FIELDS[f.name])
        elif node == 'controller_node':
            for k, spec in CONTROLLER_FIELDS.items():
                num(k, getattr(ControllerSettings(), k), spec)
            out['gain_source'] = ('yaml', 'where the gain comes from: yaml | design', None)
            out['gain'] = ([0.0, 0.0, 0.0, 0.0], 'V = K (x, theta, x\', theta\') [V/m, V/rad, V s/m, V s/rad]', None)
            out['Q'] = (list(DEFAULT_Q), 'LQR weights on (x, theta, x\', theta\')', None)
            plant('plant')
            friction('design_friction', FrictionParams())
        else:
            raise ConfigError(f'node: {node!r} is not one of sim_node, controller_node')
        return out


def nest(flat: Mapping[str, Any]) -> dict:
    """{'a.b': 1} -> {'a': {'b': 1}} (ROS parameter names to the YAML nesting)."""
    out: dict = {}
    for key, value in flat.items():
        node = out
        parts = key.split('.')
        for p in parts[:-1]:
            node = node.setdefault(p, {})
        node[parts[-1]] = value
    return out


def scenario_from_ros_params(sim_params: Mapping | None, controller_params: Mapping | None) -> Scenario:
    """Validate the two nodes' (nested) parameters; either may be None (a node needs one)."""
    if sim_params is not None:
        sim, plant, friction, truth = parse_sim(sim_params)
    else:
        sim, plant, friction, truth = SimSettings(), PlantParams(), FrictionParams(), PlantTruth()
    ctrl = parse_controller(controller_params) if controller_params is not None else ControllerSettings(
        gain=(0.0, 0.0, 0.0, 0.0))
    if sim_params is not None and controller_params is not None and ctrl.sample_rate_hz != sim.sample_rate_hz:
        raise ConfigError(f'controller_node.ros__parameters.sample_rate_hz: {ctrl.sample_rate_hz:g} Hz differs from '
                          f'sim_node.ros__parameters.sample_rate_hz: {sim.sample_rate_hz:g} Hz; the controller '
                          f'answers every sample of the simulator: give both the same rate')
    return Scenario(sim, plant, friction, truth, ctrl)


#: The nodes a scenario file has sections for.
NODE_NAMES = ('sim_node', 'controller_node', 'recorder')
#: The key of each node's section as ipfric writes it: the ROS wildcard form, which matches the
#: node in any namespace (``sim_node:`` alone matches only ``/sim_node``).
SECTION_KEYS = {name: f'/**/{name}' for name in NODE_NAMES}
#: A ROS namespace: ``/`` or ``/`` + tokens of letters, digits and ``_`` not starting with a digit.
NAMESPACE = re.compile(r'/|(/[A-Za-z_][A-Za-z0-9_]*)+')


def check_namespace(namespace: str | None, path: str = '--namespace') -> str:
    """``namespace`` as a fully qualified ROS namespace ('' or None: the root ``/``); ConfigError if not one."""
    ns = namespace or '/'
    ns = ns if ns.startswith('/') else '/' + ns
    ns = ns.rstrip('/') or '/'
    if not NAMESPACE.fullmatch(ns):
        raise ConfigError(f'{path}: {namespace!r} is not a ROS namespace; allowed: tokens of letters, digits and _ '
                          f'(not starting with a digit) separated by /, e.g. /rig1 or /lab/rig2')
    return ns


def key_matches(key: str, fqn: str) -> bool:
    """Whether the parameter-file key ``key`` applies to the node ``fqn`` (e.g. ``/rig1/sim_node``) by
    rcl's rules: ``/**`` any number of namespace tokens, ``/*`` one token, no leading ``/`` = from the root."""
    parts = ('/' + key.lstrip('/')).split('/')[1:]
    rx = ''.join('(?:/[^/]+)*' if t == '**' else '/[^/]+' if t == '*' else '/' + re.escape(t) for t in parts)
    return re.fullmatch(rx, fqn) is not None


def _merge(into: dict, more: Mapping) -> dict:
    for k, v in more.items():
        if isinstance(v, Mapping) and isinstance(into.get(k), dict):
            _merge(into[k], v)
        else:
            into[k] = dict(v) if isinstance(v, Mapping) else v
    return into


def _one_type_arrays(path: str, value: Any) -> None:
    """rcl's parameter parser takes an array of one type only: refuse ``[70, 142.5]`` here, naming it."""
    if isinstance(value, Mapping):
        for k, v in value.items():
            _one_type_arrays(f'{path}.{k}', v)
    elif isinstance(value, list) and len({type(v) for v in value}) > 1:
        kinds = ', '.join(sorted({type(v).__name__ for v in value}))
        fixed = [float(v) if isinstance(v, int) and not isinstance(v, bool) else v for v in value]
        raise ConfigError(f'{path}: {value!r} mixes {kinds}; a ROS parameter array has one type (rcl refuses the '
                          f'file): write every number with a decimal point, e.g. {fixed!r}')


def section_node(key) -> str:
    """The node name a parameter file's section key ends in: 'sim_node' of sim_node:, /**/sim_node:,
    /rig1/sim_node:."""
    return str(key).rstrip('/').rsplit('/', 1)[-1]


def node_sections(data: Mapping, namespace: str = '/', path: str | Path = '<scenario>') -> dict:
    """The ``ros__parameters`` each node of ``NODE_NAMES`` in ``namespace`` gets from a parameter
    file's ``data``, by rcl's rules: every section whose key matches the node, merged in file order;
    nodes without a matching section are left out. Keys that name no ipfric node are refused."""
    ns = check_namespace(namespace)
    found: dict = {}
    for key, section in data.items():
        last = section_node(key)
        if last not in NODE_NAMES and last not in ('*', '**'):
            raise ConfigError(f'{path}: unknown section {key!r}; allowed: sections for '
                              f'{", ".join(NODE_NAMES)} (e.g. /**/sim_node, which matches the node in any '
                              f'namespace), or /** for all')
        if not isinstance(section, Mapping) or 'ros__parameters' not in section or not isinstance(
                section['ros__parameters'], Mapping):
            raise ConfigError(f'{path}: {key}: {section!r} is not a mapping with ros__parameters:')
        _one_type_arrays(f'{str(key).lstrip("/")}.ros__parameters', section['ros__parameters'])
        for node in NODE_NAMES:
            if key_matches(str(key), f'{ns.rstrip("/")}/{node}'):
                _merge(found.setdefault(node, {}), section['ros__parameters'])
    return found


def scenario_from_sections(sections: Mapping, path: str | Path = '<scenario>', namespace: str = '/') -> Scenario:
    """The Scenario of :func:`node_sections`' result (both nodes required, a recorder section checked)."""
    where = '' if namespace in ('/', '', None) else f' in namespace {namespace}'
    for node in ('sim_node', 'controller_node'):
        if node not in sections:
            raise ConfigError(f'{path}: no section for {node}{where} (write "{SECTION_KEYS[node]}: ros__parameters:", '
                              f'which matches the node in any namespace)')
    if 'recorder' in sections:
        _check_recorder(path, sections['recorder'])
    return scenario_from_ros_params(sections['sim_node'], sections['controller_node'])


def load_scenario(path: str | Path, namespace: str = '/') -> Scenario:
    """Load a scenario parameter file as the nodes in ``namespace`` read it (both node sections required)."""
    return scenario_from_sections(node_sections(load_yaml(path), namespace, path), path, namespace)


def scenario_path(name: str | Path) -> Path:
    """A scenario file by path, or by name (``default``, ``fig7_old_gain_exponential.yaml``) among those
    of the checkout's ``config/`` and those installed in ``share/ipfric_bringup/config`` of every
    prefix of ``AMENT_PREFIX_PATH``."""
    p = Path(name)
    if p.exists() and not p.is_dir():      # a FIFO or device too: load_yaml refuses it by name
        return p
    dirs = [REPO_ROOT / 'config'] + [Path(prefix) / 'share' / 'ipfric_bringup' / 'config'
                                     for prefix in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if prefix]
    if p.name == str(name):
        for d in dirs:
            for candidate in (d / p.name, d / f'{p.name}.yaml'):
                if candidate.is_file() and candidate.name != 'paper.yaml':
                    return candidate
    known = sorted({f.stem for d in dirs if d.is_dir() for f in d.glob('*.yaml') if f.name != 'paper.yaml'})
    raise ConfigError(f'scenario {str(name)!r}: no such file, and no scenario of that name; by name: '
                      f'{", ".join(known) or "none installed"}')


#: The recorder's parameters (ipfric_record.recorder declares them).
RECORDER_PARAMS = ('output', 'scenario_file', 'use_sim_time')


def _check_recorder(path, params: Mapping) -> None:
    """The recorder's ``ros__parameters``: known names, string values (``use_sim_time`` true or false)."""
    for key, value in params.items():
        if key not in RECORDER_PARAMS:
            near = difflib.get_close_matches(str(key), RECORDER_PARAMS, 1)
            raise ConfigError(f'{path}: recorder.ros__parameters.{key}: unknown parameter'
                              + (f' (did you mean {near[0]!r}?)' if near else '')
                              + f'; allowed: {", ".join(RECORDER_PARAMS)}')
        if key == 'use_sim_time':
            if not isinstance(value, bool):
                raise ConfigError(f'{path}: recorder.ros__parameters.use_sim_time: {value!r} is not true or false')
        elif not isinstance(value, str):
            raise ConfigError(f'{path}: recorder.ros__parameters.{key}: {value!r} is not a string (a path)')
