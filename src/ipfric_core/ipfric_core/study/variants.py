"""Variants of a scenario: what the studies change in it, each change written once.

A study runs a scenario's sampled closed loop many times with one thing changed: the
sensors made exact (the paper's simulations), the friction smoothed, the velocity filter,
the feedback delay, the gain or the friction scaled, the initial angle, the encoder counts.
:func:`loop_of` turns a variant into the numbers the compiled loop takes
(:class:`~ipfric_core.study.orbit.LoopNumbers`). :data:`FIGURES` are the paper's figure presets.
"""
from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

from ..constants import REPO_ROOT
from ..physics.params import ConfigError, check_number
from ..run.scenario import CONTROLLER_FIELDS, Scenario, load_scenario
from .orbit import LoopNumbers, loop_numbers

__all__ = ['PARAMETERS', 'SENSORS', 'SCALED_SENSORS', 'FIGURES', 'FIGURE_GRIDS', 'exact_sensors', 'scenario_at',
           'cell_scenario', 'scaled_encoders', 'variant', 'load_variant', 'loop_of', 'figure_config']

#: what a continuation or a diagram varies: the delay [s], a multiple of the gain, a multiple of
#: the friction coefficients (mu_s, mu_c, eps)
PARAMETERS = ('delay', 'gain', 'friction')
#: the sensors a study runs with: exact states (the paper's simulations) or the scenario's encoders
SENSORS = ('exact', 'config')
#: which encoder count(s) :func:`scaled_encoders` scales
SCALED_SENSORS = ('angle', 'cart', 'both')

# The paper's Figures 11-12: scenario, variants (label, smoothing, line style); grids (name, theta0 range [deg])
FIGURES: dict[str, tuple[str, list[tuple[str, str | None, str]]]] = {
    '11': ('fig9_new_gain_exponential.yaml', [('sgn', 'none', '--'), ('tanh(100v)', 'tanh', '-')]),
    '12': ('fig10_new_gain_dynamic.yaml', [('dynamic', None, '-')]),
}
# theta0 = 0 is left out: with exact sensors the run stays at the equilibrium for any delay
FIGURE_GRIDS = (('full', '0.5:12:0.5'), ('zoom', '0.025:0.5:0.025'))


def figure_config(figure: str) -> Path:
    """The scenario file of the paper's Figure ``figure`` (a key of :data:`FIGURES`)."""
    return REPO_ROOT / 'config' / FIGURES[figure][0]


def exact_sensors(scn: Scenario) -> Scenario:
    """``scn`` with exact states for encoders (counts of 0)."""
    return replace(scn, sim=replace(scn.sim, cart_resolution=0.0, angle_resolution=0.0))


def scaled_encoders(scn: Scenario, scale: float, sensor: str = 'angle') -> Scenario:
    """``scn`` with the ``sensor`` encoder count(s) (:data:`SCALED_SENSORS`) times ``scale`` (0 = exact)."""
    s = scn.sim
    return replace(scn, sim=replace(
        s, cart_resolution=s.cart_resolution * (scale if sensor in ('cart', 'both') else 1.0),
        angle_resolution=s.angle_resolution * (scale if sensor in ('angle', 'both') else 1.0)))


def scenario_at(base: Scenario, name: str, value: float) -> Scenario:
    """``base`` with parameter ``name`` at ``value``: one of :data:`PARAMETERS`, or ``theta0``, the
    initial angle [rad]. A delay is rounded to whole samples (what the controller applies)."""
    if name == 'delay':
        return replace(base, controller=replace(base.controller,
                                                delay=round(value / base.sample_period) * base.sample_period))
    if name == 'gain':
        return replace(base, controller=replace(base.controller, gain=tuple(value * k for k in base.gain())))
    if name == 'friction':
        f = base.friction
        return replace(base, friction=f.replace(mu_s=value * f.mu_s, mu_c=value * f.mu_c, eps=value * f.eps))
    if name == 'theta0':
        return replace(base, sim=replace(base.sim, theta0=float(value)))
    raise ValueError(f'parameter {name!r}: expected one of {", ".join(PARAMETERS)} or theta0')


def cell_scenario(base: Scenario, tau: float, theta0_deg: float) -> Scenario:
    """``base`` with the feedback delay tau [s] (as given, not rounded) and initial angle theta0 [deg]."""
    return replace(scenario_at(base, 'theta0', math.radians(float(theta0_deg))),
                   controller=replace(base.controller, delay=float(tau)))


def variant(base: Scenario, sensors: str = 'config', smoothing: str | None = None,
            cutoff_hz: float | None = None) -> Scenario:
    """The loop a study runs ``base`` as: its encoders or exact sensors (:data:`SENSORS`), the friction
    smoothing and the velocity filter corner [Hz] replaced when given (0 Hz = raw difference)."""
    if sensors not in SENSORS:
        raise ConfigError(f'--sensors: {sensors!r} is not one of {", ".join(SENSORS)}')
    if cutoff_hz is not None:
        check_number('--cutoff-hz', cutoff_hz, CONTROLLER_FIELDS['cutoff_hz'])
        base = replace(base, controller=replace(base.controller, cutoff_hz=cutoff_hz))
    if sensors == 'exact':
        base = exact_sensors(base)
    if smoothing:
        base = replace(base, friction=base.friction.replace(smoothing=smoothing))
    return base


def load_variant(config, sensors: str = 'config', smoothing: str | None = None,
                 cutoff_hz: float | None = None) -> Scenario:
    """:func:`variant` of the scenario file ``config``."""
    return variant(load_scenario(config), sensors, smoothing, cutoff_hz)


def loop_of(base: Scenario, name: str, value: float, delay: float | None = None) -> LoopNumbers:
    """The sampled loop of ``base`` at parameter ``name`` = ``value`` (one of :data:`PARAMETERS`, or
    ``theta0`` [rad]), with the feedback delay ``delay`` [s] (default the scenario's) unless the
    parameter is the delay; a delay may fall between samples here."""
    scn = base if name == 'delay' else scenario_at(base, name, value)
    return loop_numbers(scn.make_rig().loop_spec(), scn.make_controller().loop_spec(),
                        value if name == 'delay' else base.controller.delay if delay is None else delay)
