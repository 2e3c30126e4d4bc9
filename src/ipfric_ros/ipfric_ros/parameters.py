"""Declare a scenario's ROS parameters on a node, from the ipfric_core schema.

Every parameter of a node section (``sim_node`` or ``controller_node``) is declared with
its default, a description with the unit, its type and its numeric range
(:meth:`ipfric_core.run.scenario.Scenario.flat_defaults`), then the values are nested again and
validated by :func:`ipfric_core.run.scenario.scenario_from_ros_params`, the same code that
checks a scenario file offline. Every problem is a :class:`ConfigError` naming the field.
"""
from __future__ import annotations

import array
import difflib

from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor, ParameterType
from rclpy.exceptions import InvalidParameterTypeException, InvalidParameterValueException, ParameterException
from rclpy.parameter import Parameter

from ipfric_core.physics.params import ConfigError
from ipfric_core.run.scenario import Scenario, nest, scenario_from_ros_params

from .rclpy_internals import parameter_overrides

__all__ = ['plain', 'descriptor', 'coerced', 'as_declared', 'declare', 'check_unknown', 'declare_scenario']

_TYPES = {bool: ParameterType.PARAMETER_BOOL, int: ParameterType.PARAMETER_INTEGER,
          float: ParameterType.PARAMETER_DOUBLE, str: ParameterType.PARAMETER_STRING}


def _ptype(default) -> int:
    if isinstance(default, (list, tuple)):
        if all(isinstance(v, str) for v in default) and default:
            return ParameterType.PARAMETER_STRING_ARRAY
        return ParameterType.PARAMETER_DOUBLE_ARRAY
    return _TYPES[type(default)]


def plain(value):
    """A parameter value as plain Python (arrays become lists)."""
    if isinstance(value, (array.array, list, tuple)):
        return [plain(v) for v in value]
    return value


def descriptor(name: str, default, description: str, rng=None, read_only: bool = False) -> ParameterDescriptor:
    """ParameterDescriptor with type, description and (for numbers) the allowed range."""
    ptype = _ptype(default)
    d = ParameterDescriptor(name=name, type=ptype, description=description, read_only=read_only)
    if rng is not None and ptype == ParameterType.PARAMETER_DOUBLE:
        lo, hi = (float(v) for v in rng)
        d.floating_point_range = [FloatingPointRange(from_value=lo, to_value=hi, step=0.0)]
        d.additional_constraints = f'{lo:g} <= value <= {hi:g}'
    elif rng is not None and ptype == ParameterType.PARAMETER_INTEGER:
        lo, hi = (int(v) for v in rng)
        d.integer_range = [IntegerRange(from_value=lo, to_value=hi, step=1)]
        d.additional_constraints = f'{lo} <= value <= {hi}'
    return d


def _integral(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def coerced(param: Parameter, ptype: int) -> Parameter:
    """``param`` as a double (array) where one is declared and integers were given (``duration: 5``,
    ``ros2 param set ... delay 0``); any other parameter unchanged."""
    value = param.value
    if ptype == ParameterType.PARAMETER_DOUBLE and _integral(value):
        return Parameter(param.name, Parameter.Type.DOUBLE, float(value))
    if (ptype == ParameterType.PARAMETER_DOUBLE_ARRAY and isinstance(value, (list, array.array))
            and all(_integral(v) or isinstance(v, float) for v in value)):
        return Parameter(param.name, Parameter.Type.DOUBLE_ARRAY, [float(v) for v in value])
    return param


def as_declared(node, param: Parameter) -> Parameter:
    """A pre-set parameters callback's conversion: ``param`` in the type ``node`` declared it with."""
    if not node.has_parameter(param.name):
        return param
    return coerced(param, node.describe_parameter(param.name).type)


def _coerce_override(node, name: str, ptype: int) -> None:
    """Accept integers in the parameter file where a double (array) is declared."""
    overrides = parameter_overrides(node)
    if overrides and name in overrides:
        overrides[name] = coerced(overrides[name], ptype)


def declare(node, section: str, name: str, default, description: str, rng=None,
            read_only: bool = False):
    """Declare one parameter; a bad value in the parameter file is a ConfigError naming it."""
    desc = descriptor(name, default, description, rng, read_only)
    _coerce_override(node, name, desc.type)
    try:
        return node.declare_parameter(name, default, desc).value
    except (InvalidParameterTypeException, InvalidParameterValueException, ParameterException) as exc:
        given = parameter_overrides(node).get(name)
        shown = repr(plain(given.value)) if given is not None else '?'
        allowed = f'; allowed {desc.additional_constraints}' if desc.additional_constraints else ''
        raise ConfigError(f'{section}.ros__parameters.{name}: {shown} refused ({_reason(exc)}){allowed}') from exc


def _reason(exc: Exception) -> str:
    text = str(exc).strip()
    return text.split('\n')[0][:200]


def check_unknown(node, section: str) -> None:
    """Refuse names in the parameter file that the node does not declare (typos)."""
    overrides = parameter_overrides(node) or {}
    unknown = sorted(n for n in overrides if not node.has_parameter(n) and not n.startswith('qos_overrides.'))
    if not unknown:
        return
    known = sorted(node.list_parameters([], 0).names)
    hints = []
    for n in unknown:
        close = difflib.get_close_matches(n, known, n=1)
        hints.append(f'{n!r}' + (f' (did you mean {close[0]!r}?)' if close else ''))
    raise ConfigError(f'{section}.ros__parameters: unknown parameter(s) {", ".join(hints)}')


#: What a node's section must give (as a scenario file must): a friction model for the simulator,
#: a gain (or a friction model to design it on) for the controller.
REQUIRED = {'sim_node': ('friction.model',), 'controller_node': ('gain', 'design_friction.model')}


def _check_given(node, section: str) -> None:
    """Refuse to run on schema defaults: a node whose parameter file has no section for it (e.g.
    ``sim_node:`` when the node runs in a namespace) would otherwise run a scenario nobody wrote."""
    given = parameter_overrides(node) or {}
    if not any(name in given for name in REQUIRED[section]):
        fqn = node.get_fully_qualified_name()
        raise ConfigError(
            f'{section}.ros__parameters: no scenario parameters for node {fqn} (none of '
            f'{", ".join(REQUIRED[section])}): give a parameter file with a section that matches the node, e.g. '
            f'"/**/{section}:" (any namespace; "{section}:" matches only /{section}), as config/*.yaml have')


def declare_scenario(node, section: str, read_only=True) -> Scenario:
    """Declare the parameters of ``section`` on ``node`` and return the validated Scenario.

    ``read_only``: True (all), or a collection of names that cannot change at run time.
    """
    defaults = Scenario.flat_defaults(section)
    _check_given(node, section)
    values = {}
    for name, (default, doc, rng) in defaults.items():
        ro = read_only is True or (read_only is not False and name in read_only)
        values[name] = plain(declare(node, section, name, default, doc, rng, ro))
    nested = nest(values)
    if section == 'sim_node':
        return scenario_from_ros_params(nested, None)
    return scenario_from_ros_params(None, nested)
