"""A Model is an ordered set of effects evaluated together: Stokes vector, Mueller matrix, DOP, AoP, BRDF.

The evaluation is one JAX function of (parameter values, measurement angles), compiled with ``jax.jit``
once per model structure, output kind and array shapes, and reused by every Model built from the same
effects. Parameter sets are padded to a few bucket sizes so that the walkers, batches and remainders of
an inversion do not each compile their own program. Callers see numpy arrays in and out.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np

from ..errors import ParameterError, SpacepolError, UnknownNameError
from .builtin_effects import Specular
from .effect import Context, DepolarizedLobe, Effect
from .geometry import Geometry
from .parameter import Parameter
from .plugin_guard import checking_outputs, culprit, effect_failure, is_plugin, untraceable
from .registry import registry

_COMPILED: dict = {}  # (effects' structure, mueller, fixed values) -> jitted evaluation


@dataclass
class Prediction:
    """Model output.  ``stokes`` is (4, *shape) for unpolarized incidence of unit irradiance
    (so S0 is the BRDF in sr^-1); ``mueller`` is (4, 4, *shape) when asked for."""

    stokes: np.ndarray
    dop: np.ndarray  # measured DOP (after any estimator effect such as dop_bias)
    mueller: np.ndarray | None = None

    @property
    def brdf(self):
        return self.stokes[0]

    @property
    def physical_dop(self):
        return _dop(self.stokes)

    @property
    def aop_deg(self):
        """Angle of polarization from the s direction towards p, degrees in (-90, 90]."""
        return 0.5 * np.degrees(np.arctan2(self.stokes[2], self.stokes[1]))


def _dop(stokes):
    """|S_pol| / S0 (0 where S0 = 0), numpy or JAX arrays."""
    xp = jnp if isinstance(stokes, jax.Array) else np
    s0 = stokes[0]
    pol = xp.sqrt(stokes[1] ** 2 + stokes[2] ** 2 + stokes[3] ** 2)
    lit = s0 > 0
    # |S| <= S0 holds for every lobe; rounding may push a ratio an ulp above 1.
    return xp.where(lit, xp.minimum(pol / xp.where(lit, s0, 1.0), 1.0), 0.0)


def bucket(n_sets: int) -> int:
    """Parameter sets are padded to this many: powers of two up to 64, then multiples of a quarter of the
    largest power of two below (at most 25 % padding, four compiled sizes per octave)."""
    if n_sets <= 64:
        return 1 << max(0, (n_sets - 1).bit_length())
    step = (1 << (n_sets.bit_length() - 1)) // 4
    return -(-n_sets // step) * step


def _structure(effects) -> tuple:
    """What decides the compiled program: built-in effects by class (they hold no state), plug-ins by instance."""
    return tuple(e if is_plugin(e) else type(e) for e in effects)


class Model:
    def __init__(self, effects):
        self.effects: list[Effect] = [self._instance(e) for e in effects]
        self._check()

    @staticmethod
    def _instance(effect) -> Effect:
        if isinstance(effect, str):
            effect = registry.get(effect)
        return effect() if isinstance(effect, type) else effect

    @classmethod
    def from_string(cls, spec: str) -> "Model":
        return cls([registry.get(name) for name in registry.expand(spec)])

    def __add__(self, other):
        if isinstance(other, str):  # names resolve in the combined model ("paper" + "polarized_diffuse")
            others = [registry.get(name) for name in registry.expand(other)]
        else:
            others = other.effects if isinstance(other, Model) else [other]
        return Model(self.effects + list(others))

    @property
    def name(self) -> str:
        return "+".join(e.name for e in self.effects)

    def __repr__(self):
        return f"Model('{self.name}')"

    def _check(self):
        names = [e.name for e in self.effects]
        if len(set(names)) != len(names):
            raise UnknownNameError(f"model '{self.name}': an effect appears twice")
        for e in self.effects:
            for need in e.requires:
                if need not in names:
                    raise UnknownNameError(f"model '{self.name}': effect '{e.name}' needs '{need}' in the model")
            for bad in e.excludes:
                if bad in names:
                    raise UnknownNameError(f"model '{self.name}': '{e.name}' replaces '{bad}'; use one of them")
        owner: dict[str, str] = {}
        for e in self.effects:
            for p in e.parameters:
                if p.name in owner:
                    raise ParameterError(
                        f"model '{self.name}': parameter '{p.name}' of effect '{e.name}' "
                        f"collides with effect '{owner[p.name]}'"
                    )
                owner[p.name] = e.name
        self._owner = owner
        removed = {r for e in self.effects for r in e.removes}
        self._parameters = [p for e in self.effects for p in e.parameters if p.name not in removed]
        self._names = {p.name for p in self._parameters}

    @property
    def parameters(self) -> list[Parameter]:
        """Every parameter the model uses, fixed ones included, in effect order."""
        return list(self._parameters)

    @property
    def free_parameters(self) -> list[Parameter]:
        return [p for p in self._parameters if not p.fixed]

    def parameter(self, name: str) -> Parameter:
        for p in self._parameters:
            if p.name == name:
                return p
        raise UnknownNameError(
            f"model '{self.name}' has no parameter '{name}' (it has: {', '.join(p.name for p in self._parameters)})"
        )

    def owner(self, name: str) -> str:
        return self._owner[name]

    def defaults(self) -> dict[str, float]:
        return {p.name: p.default for p in self._parameters}

    def _resolve(self, params: dict, check: bool = True) -> tuple[dict, tuple]:
        if not self._names.issuperset(params):
            unknown = sorted(set(params) - self._names)
            raise UnknownNameError(
                f"model '{self.name}' has no parameter(s) {', '.join(unknown)} (it has: {', '.join(sorted(self._names))})"
            )
        values, batch = {}, ()
        for p in self._parameters:
            v = params.get(p.name, p.default)
            if check:
                p.check(v, where=f"model '{self.name}'")
            if np.ndim(v) == 0:
                values[p.name] = float(v)
                continue
            v = np.asarray(v, dtype=float)
            if v.ndim > 1 or (batch and v.shape != batch and v.shape != (1,)):
                raise ParameterError("parameter values must be scalars or 1-d arrays of one length (one entry per parameter set)")
            batch = batch if (batch and v.shape == (1,)) else v.shape
            # (P,) -> (P, 1) so parameter sets broadcast against the N geometries.
            values[p.name] = v[:, None]
        return values, batch

    def evaluate(self, params: dict, geometry: Geometry, mueller: bool = False, check: bool = True) -> Prediction:
        """Evaluate for parameter sets (scalars or arrays of length P) at N geometries.

        Missing parameters take their defaults.  Returns arrays of shape (N,) for scalar
        parameters or (P, N) for P parameter sets.  ``check=False`` skips the test for
        physically impossible values (for callers that already applied the priors).
        A plug-in effect that raises, exits or cannot be traced becomes one EffectError naming it.
        """
        with self._naming_plugin_failures():
            return self._compiled_evaluate(params, geometry, mueller, check)

    def check_plugins(self, params: dict, geometry: Geometry) -> Prediction:
        """Evaluate once uncompiled, every plug-in hook's output checked for NaN/inf, then compiled (an
        EffectError names the effect that failed, returned non-finite values or cannot be traced)."""
        with self._naming_plugin_failures(), checking_outputs(self.effects):
            values, batch = self._resolve(params, check=False)
            values = {k: jnp.asarray(v) for k, v in values.items()}
            _evaluate_values(self.effects, values, batch, Geometry.from_terms(geometry.device_terms(), geometry.all_visible), False)
        return self.evaluate(params, geometry, check=False)

    @contextmanager
    def _naming_plugin_failures(self):
        try:
            yield
        except SpacepolError:
            raise
        except (Exception, SystemExit) as exc:
            effect = culprit(self.effects, exc)
            if effect is None:
                raise
            raise (untraceable(effect, exc) or effect_failure(effect, exc)) from exc

    def _compiled_evaluate(self, params, geometry, mueller, check) -> Prediction:
        values, batch = self._resolve(params, check)
        # Given values are traced; defaults (fixed parameters nobody set) are compiled in as constants.
        traced = {k: v for k, v in values.items() if k in params}
        fixed = tuple(sorted((k, v) for k, v in values.items() if k not in params))
        n_sets = batch[0] if batch else 0
        padded = bucket(n_sets) if n_sets else 0
        if padded > n_sets:  # repeat the last set (always a valid one)
            traced = {k: np.pad(v, ((0, padded - n_sets), (0, 0)), mode="edge") if np.shape(v)[:1] == batch else v
                      for k, v in traced.items()}
        key = (_structure(self.effects), mueller, fixed, geometry.all_visible)
        run = _COMPILED.get(key)
        if run is None:
            run = _COMPILED[key] = _compile(self.effects, dict(fixed), mueller, geometry.all_visible)
        total, dop = run(traced, geometry.device_terms())
        total, dop = np.asarray(total), np.asarray(dop)
        if padded > n_sets:
            total, dop = total[..., :n_sets, :], dop[:n_sets]
        stokes = total[:, 0] if mueller else total
        return Prediction(stokes=stokes, dop=dop, mueller=total if mueller else None)

    def dop(self, params: dict, geometry: Geometry):
        return self.evaluate(params, geometry).dop


def _compile(effects, fixed: dict, mueller: bool, all_visible: bool):
    def run(traced, terms):
        values = {**fixed, **traced}
        sizes = [v.shape[0] for v in traced.values() if v.ndim == 2]
        batch = (max(sizes),) if sizes else ()
        return _evaluate_values(effects, values, batch, Geometry.from_terms(terms, all_visible), mueller)

    return jax.jit(run)


def _once(value, shape):
    """A hook's output that does not vary over parameter sets (the paper's shadowing at fixed constants) is
    computed once: without the barrier XLA on a CPU fuses it into every (set, geometry) element that uses
    it and recomputes its trigonometry there."""
    if value is None or not shape or np.ndim(value) == 0 or len(shape) < 2 or np.shape(value)[-2:-1] == shape[-2:-1]:
        return value
    return jax.lax.optimization_barrier(value)


def _evaluate_values(effects, values: dict, batch: tuple, geometry: Geometry, mueller: bool):
    """The model's hooks in their order (``effect``'s docstring): (Stokes or Mueller total, measured DOP)."""
    geo = geometry
    for e in effects:
        geo = e.transform_geometry(values, geo)
    shape = np.broadcast_shapes(batch + (1,) if batch else (), geo.shape)
    ctx = Context(values, geo, mueller, shape)
    for e in effects:
        e.configure(ctx)

    specular = next((e for e in effects if isinstance(e, Specular)), None)
    if specular is not None:
        factor = None
        for e in effects:
            f = _once(e.specular_factor(ctx), shape)
            if f is not None:
                factor = f if factor is None else factor * f
        total = specular.specular_lobe(ctx, factor)
        for e in effects:
            total = e.modify_specular(ctx, total)
    else:
        total = ctx.zeros()
    lead = (4, 4) if mueller else (4,)
    total = jnp.broadcast_to(total, lead + shape)
    for e in effects:
        extra = e.lobe(ctx)
        if isinstance(extra, DepolarizedLobe):
            extra = DepolarizedLobe(_once(extra.intensity, shape))
            total = extra.add_to(total, mueller)
        elif extra is not None:
            total = total + extra
    for e in effects:
        total = e.modify_stokes(ctx, total)
    if not geo.all_visible:
        total = jnp.where(geo.visible, total, 0.0)
    dop = _dop(total[:, 0] if mueller else total)
    for e in effects:
        dop = e.modify_dop(ctx, dop)
    return total, dop


def build_model(spec: str | Model) -> Model:
    return spec if isinstance(spec, Model) else Model.from_string(spec)
