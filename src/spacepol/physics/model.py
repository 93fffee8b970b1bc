"""A Model is an ordered set of effects evaluated together: Stokes vector, Mueller matrix, DOP, AoP, BRDF.

The evaluation is one compiled JAX function (``compiled``); callers see numpy arrays in and out.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass

import jax.numpy as jnp
import numpy as np

from .._runtime import ensure_double_precision
from ..errors import ParameterError, SpacepolError, UnknownNameError
from .arrays import array_module
from .compiled import degree_of_polarization, evaluate_values, jitted, packed
from .effect import Effect
from .geometry import Geometry
from .parameter import Parameter
from .plugin_guard import checking_outputs, culprit, effect_failure, is_plugin, untraceable
from .registry import registry


@dataclass
class Prediction:
    """Model output.  ``stokes`` is (4, *shape) for unpolarized incidence of unit irradiance
    (so S0 is the BRDF in sr^-1); ``mueller`` is (4, 4, *shape) when asked for."""

    stokes: np.ndarray
    dop: np.ndarray  # measured DOP (after any estimator effect such as dop_bias)
    mueller: np.ndarray | None = None

    @classmethod
    def from_total(cls, total, dop, mueller: bool) -> "Prediction":
        """From the model's total: a Mueller matrix (its first column is the Stokes vector for unpolarized
        incidence) when ``mueller``, else the Stokes vector itself."""
        return cls(stokes=total[:, 0] if mueller else total, dop=dop, mueller=total if mueller else None)

    @property
    def brdf(self):
        """The BRDF (sr^-1) for unpolarized incidence: S0."""
        return self.stokes[0]

    @property
    def physical_dop(self):
        """The DOP of the Stokes vector itself, before any measurement effect on the DOP (e.g. dop_bias)."""
        return degree_of_polarization(self.stokes)

    @property
    def aop_deg(self):
        """Angle of polarization from the s direction towards p, degrees in (-90, 90]."""
        xp = array_module(self.stokes)
        return 0.5 * xp.degrees(xp.arctan2(self.stokes[2], self.stokes[1]))

    def require_finite(self, params: dict, model_name: str) -> "Prediction":
        """This prediction, or a ParameterError naming the parameters where the model's output overflowed or is not
        a number (values far outside any measured material: the numbers written would be meaningless)."""
        stokes = np.asarray(self.stokes, float)
        # a Stokes vector whose squares overflow gives a DOP of 0 or 1 that means nothing
        bad = ~np.isfinite(stokes) | (np.abs(stokes) > _LARGEST_STOKES) | ~np.isfinite(np.asarray(self.dop, float))
        if np.any(bad):
            given = ", ".join(f"{k} = {float(v):g}" for k, v in params.items() if np.ndim(v) == 0)
            raise ParameterError(f"model '{model_name}' gives no finite output at {given}: "
                                 "a value too large or too small for the model to evaluate")
        return self


# Stokes components above this overflow when squared (the DOP's sqrt(s1^2 + s2^2 + s3^2))
_LARGEST_STOKES = 1e150


class Model:
    """A pBRDF model: a list of effects (registered names, classes or instances) that together predict the
    Mueller matrix, BRDF and DOP at each geometry; ``from_string("paper+polarized_diffuse")`` builds one from
    DESIGN.md's names, ``parameters`` lists its parameters with their default priors."""

    def __init__(self, effects):
        ensure_double_precision()  # the physics is wrong in float32, JAX's default
        self.effects: list[Effect] = [self._instance(e) for e in effects]
        self._check()

    @staticmethod
    def _instance(effect) -> Effect:
        if isinstance(effect, str):
            effect = registry.get(effect)
        return effect() if isinstance(effect, type) else effect

    @classmethod
    def from_string(cls, spec: str) -> "Model":
        """The model of an effect list joined by ``+`` or a preset name (``paper``); unknown names and effects that do
        not compose are one line."""
        return cls([registry.get(name) for name in registry.expand(spec)])

    def __add__(self, other):
        if isinstance(other, str):  # names resolve in the combined model ("paper" + "polarized_diffuse")
            others = [registry.get(name) for name in registry.expand(other)]
        else:
            others = other.effects if isinstance(other, Model) else [other]
        return Model(self.effects + list(others))

    @property
    def name(self) -> str:
        """The model's effects joined by ``+``."""
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
        """The parameters that are not fixed."""
        return [p for p in self._parameters if not p.fixed]

    def parameter(self, name: str) -> Parameter:
        """The parameter of this name; an unknown name is one line listing the model's parameters."""
        for p in self._parameters:
            if p.name == name:
                return p
        raise UnknownNameError(
            f"model '{self.name}' has no parameter '{name}' (it has: {', '.join(p.name for p in self._parameters)})"
        )

    def owner(self, name: str) -> str:
        """The name of the effect that declares parameter ``name``."""
        return self._owner[name]

    def defaults(self) -> dict[str, float]:
        """{parameter: default value} of every parameter."""
        return {p.name: p.default for p in self._parameters}

    def _resolve(self, params: dict, check: bool = True) -> tuple[dict, tuple]:
        if not self._names.issuperset(params):
            unknown = sorted(set(params) - self._names)
            raise UnknownNameError(
                f"model '{self.name}' has no parameter(s) {', '.join(unknown)} (it has: {', '.join(sorted(self._names))})"
            )
        values, arrays = {}, {}
        for p in self._parameters:
            v = params.get(p.name, p.default)
            if check:
                p.check(v, where=f"model '{self.name}'")
            if isinstance(v, float | int):  # the common scalar first (np.ndim would make an array of it)
                values[p.name] = float(v)
                continue
            v = np.asarray(v, dtype=float)
            if v.ndim == 0:
                values[p.name] = float(v)
                continue
            if v.ndim > 1:
                raise ParameterError("parameter values must be scalars or 1-d arrays of one length (one entry per parameter set)")
            values[p.name] = arrays[p.name] = v
        # P is the longest length given; a length-1 array is one set shared by all, in any position
        lengths = {v.shape[0] for v in arrays.values()}
        batch = (max(lengths),) if lengths else ()
        if lengths - {1} - set(batch):
            given = ", ".join(f"{k}: {v.shape[0]}" for k, v in arrays.items())
            raise ParameterError(f"model '{self.name}': parameter arrays of different lengths ({given}); give each a "
                                 "scalar or one value per parameter set")
        # (P,) -> (P, 1) so parameter sets broadcast against the N geometries.
        return {k: arrays[k][:, None] if k in arrays else v for k, v in values.items()}, batch

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
        if not any(is_plugin(e) for e in self.effects):  # built-in effects are not guarded: nothing to check
            return self.evaluate(params, geometry, check=False)
        with self._naming_plugin_failures(), checking_outputs(self.effects):
            values, batch = self._resolve(params, check=False)
            values = {k: jnp.asarray(v) for k, v in values.items()}
            evaluate_values(self.effects, values, batch, Geometry.from_terms(geometry.device_terms(), geometry.all_visible), False)
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
        total, dop = self._run(params, geometry, mueller, check, dop_only=False)
        return Prediction.from_total(total, dop, mueller)

    def _run(self, params, geometry, mueller, check, dop_only):
        """The compiled program's outputs, [total, dop] or [dop], as numpy arrays without the sets' padding."""
        values, batch = self._resolve(params, check)
        # Given values are traced; defaults (fixed parameters nobody set) are compiled in as constants.
        traced = {k: v for k, v in values.items() if k in params}
        fixed = {k: v for k, v in values.items() if k not in params}
        n_sets = batch[0] if batch else 0
        run = jitted(self.effects, tuple(traced), fixed, mueller, geometry.all_visible, dop_only)
        outputs = [np.asarray(a) for a in run(packed(traced, n_sets), geometry.device_terms())]
        if n_sets:  # the padding off: sets are the second-to-last axis of every output
            outputs = [a[..., :n_sets, :] for a in outputs]
        return outputs

    @property
    def inner(self) -> "Model":
        """The Model evaluated on each part of the data (itself; a SpectralModel's is its per-wavelength model)."""
        return self

    def parts(self, geometry: Geometry) -> list:
        """[(rows, geometry of those rows, params -> this model's params)]: one part, every row."""
        return [(slice(None), geometry, lambda values: values)]

    def dop(self, params: dict, geometry: Geometry, check: bool = True) -> np.ndarray:
        """The measured DOP alone, (N,) or (P, N): what ``evaluate(...).dop`` gives, from a program that does
        not write the Stokes vector out (1.8x faster for the paper's model, 4,096 sets x 84 geometries)."""
        with self._naming_plugin_failures():
            (dop,) = self._run(params, geometry, False, check, dop_only=True)
        return dop


Effect._model_type = Model  # effect + effect -> Model (physics.effect)
