"""The model under identification: a declared plant and friction law, and the effects added.

Every parameter is a :class:`Param` with a unit, physical bounds and a ``free`` flag (as
in MuJoCo's sysid toolbox). Known constants of the plant (masses, pendulum length, motor
alpha and beta: paper Table 1 and eq. 2) are frozen unless the user frees them by name;
the friction of the declared law (levels in N, so the same for any normal force) and the
parameters of each added effect are fitted. :meth:`Model.vectors` turns the values into
the arguments of :mod:`ipfric_core.physics` (plant vector, friction vector, forces fixed
to the track, input and sensor effects): the model that is fitted is the model the
simulator runs, and :meth:`Model.friction_params` / :meth:`Model.plant_truth` export it
whole: the effects' parameters are the fields of :class:`~ipfric_core.physics.rig.PlantTruth`.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

from ..physics.friction import friction_vector
from ..physics.params import ConfigError, FrictionParams, PlantParams
from ..physics.plant import plant_vector
from ..physics.rig import PlantTruth
from .effects import BASE_MODELS, EFFECTS, PARAMS, lower_bound, static_level

__all__ = ['Param', 'PLANT_KNOWN', 'LAW_PARAMS', 'FRICTION_FITTED', 'LADDER_EFFECTS', 'TRUTH_PARAMS', 'param',
           'ModelVectors', 'Model', 'declared', 'read_declared', 'load_declared']


@dataclass(frozen=True)
class Param:
    """One parameter: value, unit, bounds, whether it is fitted, what it is."""

    name: str
    value: float
    unit: str
    lo: float
    hi: float
    free: bool = True
    doc: str = ''

    def at_bound(self, tol: float) -> bool:
        """True when the fitted value sits within ``tol`` of a bound."""
        return self.free and (self.value - self.lo <= tol or self.hi - self.value <= tol)


#: the plant's known constants (Table 1 and eq. 2): frozen unless freed by name
PLANT_KNOWN = ('M', 'm', 'l', 'alpha', 'beta')
#: the friction parameters each declared law fits (levels in N: the same for any normal force)
LAW_PARAMS = {'viscous': ('eps',), 'coulomb': ('Fc', 'Fs_excess', 'eps'),
              'exponential': ('Fc', 'Fs_excess', 'eps', 'v_s'),
              'dynamic': ('Fc', 'Fs_excess', 'eps', 'v_s', 'sigma0', 'sigma1')}
#: every friction parameter a declared law may fit
FRICTION_FITTED = LAW_PARAMS['dynamic']

#: Effects the ladder adds, from the one library of :mod:`ipfric_core.ident.effects` (the base
#: law's coulomb, stribeck and presliding are the declared friction here).
LADDER_EFFECTS = ('deadzone', 'saturation', 'delay', 'lag', 'cogging', 'asymmetry', 'offset', 'sensor_bias',
                  'backlash', 'drive_backlash')
#: the effects' parameters that are fields of PlantTruth (all of them)
TRUTH_PARAMS = tuple(n for e in LADDER_EFFECTS for n in EFFECTS[e].params)


def param(name: str, value: float, free: bool, law: str = 'viscous') -> Param:
    """Parameter ``name`` of :data:`~ipfric_core.ident.effects.PARAMS` at ``value``, within its bounds under
    the friction law ``law`` (:func:`~ipfric_core.ident.effects.lower_bound`)."""
    s = PARAMS[name]
    return Param(name, float(value), s.unit, lower_bound(name, BASE_MODELS[law]), s.hi, free, s.doc)


@dataclass(frozen=True)
class ModelVectors:
    """The arguments of the physics functions for one set of parameter values: the plant vector,
    the friction vector and the undeclared effects (input delay not rounded)."""

    pp: tuple
    fp: tuple
    truth: PlantTruth


@dataclass(frozen=True)
class Model:
    """A declared plant and friction law plus added effects, with every parameter.

    The back-EMF beta and the viscous slope eps act alike (F = alpha V - (beta + eps) x', paper eq. 2):
    they are never fitted together. Where beta is fitted, eps is held (:meth:`with_free`,
    :meth:`with_law`) and keeps its value (:meth:`with_values`): the whole viscous term is beta's."""

    law: str                       # viscous, coulomb, exponential or dynamic (a key of LAW_PARAMS)
    params: tuple                  # Param, in order
    effects: tuple = ()            # names of EFFECTS added, in order
    gamma: float = 2.0             # Stribeck form factor (declared, not fitted)
    g: float = 9.8
    normal_force: float = 1.0      # F_N [N] of the friction coefficients mu
    pendulum: bool = True          # the pendulum is attached (else m is taken as 0)

    def __getitem__(self, name: str) -> float:
        return self.param(name).value

    def param(self, name: str) -> Param:
        for p in self.params:
            if p.name == name:
                return p
        raise KeyError(name)

    def get(self, name: str, default: float = 0.0) -> float:
        return self[name] if any(p.name == name for p in self.params) else default

    @property
    def free(self) -> list[Param]:
        return [p for p in self.params if p.free]

    def with_values(self, values: dict) -> Model:
        """This model with the values of ``values`` (but a held eps beside a fitted beta: see the class)."""
        keep = {'eps'} if self.viscous_in_beta else set()
        return replace(self, params=tuple(replace(p, value=float(values[p.name]))
                                          if p.name in values and p.name not in keep else p for p in self.params))

    @property
    def viscous_in_beta(self) -> bool:
        """True where beta is fitted: the viscous slope eps is then held, the viscous term is beta's."""
        return any(p.name == 'beta' and p.free for p in self.params)

    def with_effect(self, name: str, starts: dict | None = None) -> Model:
        """This model with effect ``name`` added (its parameters free, at ``starts`` or 0)."""
        new = tuple(param(n, (starts or {}).get(n, 0.0), True) for n in EFFECTS[name].params)
        return replace(self, params=self.params + new, effects=self.effects + (name,))

    def freeing(self, names) -> Model:
        """Known constants ``names`` fitted too (a refit of a known constant tests the model)."""
        bad = [n for n in names if n not in PLANT_KNOWN]
        if bad:
            raise ConfigError(f'--free: {", ".join(bad)} is not a plant constant; allowed: {", ".join(PLANT_KNOWN)}')
        return self.with_free(names)

    def with_free(self, names) -> Model:
        """This model with the parameters ``names`` fitted (the others as they are); but eps where beta is
        fitted: held there, at its value (see the class)."""
        beta = self.viscous_in_beta or 'beta' in names
        return replace(self, params=tuple(replace(p, free=False) if beta and p.name == 'eps'
                                          else replace(p, free=True) if p.name in names else p for p in self.params))

    def law_fitted(self) -> tuple:
        """The parameters that fit this model's friction law: its :data:`LAW_PARAMS`, with beta in place of
        eps where the viscous term is beta's (see the class)."""
        return tuple('beta' if n == 'eps' and self.viscous_in_beta else n for n in LAW_PARAMS[self.law])

    def holding(self, values: dict) -> Model:
        """This model with the parameters of ``values`` held there (not fitted)."""
        return replace(self, params=tuple(replace(p, value=float(values[p.name]), free=False) if p.name in values
                                          else p for p in self.params))

    def with_bounds(self, name: str, lo: float, hi: float) -> Model:
        """This model with parameter ``name`` confined to [lo, hi] (within its physical range)."""
        return replace(self, params=tuple(replace(p, lo=max(p.lo, lo), hi=min(p.hi, hi)) if p.name == name else p
                                          for p in self.params))

    def fitted(self, names) -> bool:
        """True when every parameter of ``names`` this model has is fitted (eps by beta, see the class)."""
        return all(p.free or (p.name == 'eps' and self.viscous_in_beta) for p in self.params if p.name in names)

    def with_law(self, law: str, starts: dict) -> Model:
        """This model with the friction law ``law`` (one of :data:`LAW_PARAMS`): its parameters fitted, at
        this model's values where it has them, else at ``starts``; the plant and the effects kept."""
        own = set(LAW_PARAMS[law])
        kept = [p for p in self.params if p.name not in FRICTION_FITTED]
        new = [param(n, max(self.get(n, starts[n]) if any(p.name == n for p in self.params) else starts[n],
                            lower_bound(n, BASE_MODELS[law])), not (n == 'eps' and self.viscous_in_beta), law)
               for n in LAW_PARAMS[law] if n in own]
        plant = [p for p in kept if p.name in PLANT_KNOWN]
        rest = [p for p in kept if p.name not in PLANT_KNOWN]
        return replace(self, law=law, params=tuple(plant + new + rest))

    def without(self, effect: str) -> Model:
        """This model without effect ``effect`` (and its parameters)."""
        own = set(EFFECTS[effect].params)
        return replace(self, params=tuple(p for p in self.params if p.name not in own),
                       effects=tuple(e for e in self.effects if e != effect))

    def friction_params(self) -> FrictionParams:
        """The friction law with its fitted values as coefficients (F_N = normal_force)."""
        fn = self.normal_force
        fc = self.get('Fc')
        bristle = self.law == 'dynamic'
        base = FrictionParams()
        return FrictionParams(model=self.law, eps=self['eps'], mu_c=fc / fn,
                              mu_s=static_level(fc, self.get('Fs_excess')) / fn, v_s=self.get('v_s', 0.105),
                              gamma=self.gamma, sigma0=self['sigma0'] if bristle else base.sigma0,
                              sigma1=self['sigma1'] if bristle else base.sigma1)

    def plant_params(self) -> PlantParams:
        return PlantParams(M=self['M'], m=max(self['m'], 1e-6), l=self['l'], g=self.g,
                           alpha=self['alpha'], beta=self['beta'])

    def plant_truth(self, dt: float | None = None) -> PlantTruth:
        """The added effects as the simulator's ``plant_truth`` (with a sample period ``dt`` [s], the
        input delay rounded to whole samples, as a rig applies it); the direction dependence of the
        friction (asymmetry) is the truth's too."""
        values: dict = {n: self.get(n) for n in TRUTH_PARAMS if any(p.name == n for p in self.params)}
        if dt is not None and 'input_delay_s' in values:
            values['input_delay_s'] = round(values['input_delay_s'] / dt) * dt
        return PlantTruth(**values)

    def vectors(self) -> ModelVectors:
        pp = list(plant_vector(self.plant_params()))
        if not self.pendulum:
            pp[1] = 0.0
        truth = self.plant_truth()
        return ModelVectors(tuple(pp), friction_vector(truth.true_friction(self.friction_params()),
                                                       self.normal_force), truth)


def declared(plant: PlantParams, friction: FrictionParams, pendulum: bool) -> Model:
    """The declared model, every parameter at its declared value and none fitted."""
    fn = plant.normal_force if pendulum else plant.M * plant.g
    if friction.model not in LAW_PARAMS:
        raise ConfigError(f'friction.model: {friction.model!r} cannot be identified; allowed: '
                          f'{", ".join(LAW_PARAMS)}')
    params = [param(k, getattr(plant, k), False) for k in PLANT_KNOWN]
    values = {'Fc': friction.mu_c * fn, 'Fs_excess': (friction.mu_s - friction.mu_c) * fn,
              'eps': friction.eps, 'v_s': friction.v_s, 'sigma0': friction.sigma0, 'sigma1': friction.sigma1}
    params += [param(k, values[k], False, friction.model) for k in LAW_PARAMS[friction.model]]
    return Model(friction.model, tuple(params), (), friction.gamma, plant.g, fn, pendulum)


def read_declared(path, law: str) -> tuple[PlantParams | None, FrictionParams]:
    """The declared plant and friction law of file ``path``, read once: a scenario (its sim_node plant
    and friction), a paper-style file (plant, and friction named by law: the ``law`` entry), or a
    file with only ``plant:`` (friction: the paper's ``law``, Table 2 for coulomb, Table 3 for
    exponential). No file: no plant (the caller's: a bag's stored scenario, or Table 1) and the
    paper's ``law``."""
    from ..design.paperconfig import DEFAULT_CONFIG
    from ..physics.params import check_keys, load_yaml
    if law not in LAW_PARAMS:
        raise ConfigError(f'--base: {law!r} is not a law the ladder fits; allowed: {", ".join(LAW_PARAMS)}')
    paper = {name: FrictionParams.from_dict(v, f'{DEFAULT_CONFIG}: friction.{name}')
             for name, v in load_yaml(DEFAULT_CONFIG)['friction'].items()}
    friction = next(f for f in paper.values() if f.model == law)
    if path is None:
        return None, friction
    from ..run.scenario import NODE_NAMES, load_scenario, section_node
    data = load_yaml(path)
    if isinstance(data, dict) and any(section_node(k) in NODE_NAMES for k in data):
        scn = load_scenario(path)       # sections sim_node:, /**/sim_node:, /rig1/sim_node: ...
        return scn.plant, scn.friction
    check_keys(str(path), data, {'plant', 'friction', 'design'}, {'plant'})
    plant = PlantParams.from_dict(data['plant'], f'{path}: plant')
    fr = data.get('friction')
    if isinstance(fr, dict) and 'model' in fr:
        friction = FrictionParams.from_dict(fr, f'{path}: friction')
    elif isinstance(fr, dict) and law in fr:
        friction = FrictionParams.from_dict(fr[law], f'{path}: friction.{law}')
    return plant, friction


def load_declared(path, law: str, pendulum: bool, plant: PlantParams | None = None) -> Model:
    """The declared model of file ``path`` (:func:`read_declared`); without a plant there, ``plant``
    (a bag's stored scenario) or Table 1."""
    declared_plant, friction = read_declared(path, law)
    return declared(declared_plant or plant or PlantParams(), friction, pendulum)
