"""A Model is an ordered set of effects evaluated together: Stokes vector, Mueller matrix, DOP, AoP, BRDF."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, SpacepolError, UnknownNameError
from .builtin_effects import Specular
from .effect import Context, DepolarizedLobe, Effect
from .geometry import Geometry
from .parameter import Parameter
from .plugin_guard import checking_outputs, culprit, effect_failure
from .registry import registry


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
    if stokes.ndim == 3 and stokes.dtype == np.float64:
        from .kernels import stokes_dop

        out = np.empty(stokes.shape[1:])
        stokes_dop(np.ascontiguousarray(stokes), out)
        return out
    s0 = stokes[0]
    pol = np.sqrt(stokes[1] ** 2 + stokes[2] ** 2 + stokes[3] ** 2)
    out = np.zeros_like(s0)
    np.divide(pol, s0, out=out, where=s0 > 0)
    # |S| <= S0 holds for every lobe; rounding may push a ratio an ulp above 1.
    return np.minimum(out, 1.0)


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
        A plug-in effect that raises or exits becomes one EffectError naming it.
        """
        try:
            return self._evaluate(params, geometry, mueller, check)
        except SpacepolError:
            raise
        except (Exception, SystemExit) as exc:
            effect = culprit(self.effects, exc)
            if effect is None:
                raise
            raise effect_failure(effect, exc) from exc

    def check_plugins(self, params: dict, geometry: Geometry) -> Prediction:
        """Evaluate once with every plug-in hook's output checked for NaN/inf (an EffectError names it)."""
        with checking_outputs(self.effects):
            return self.evaluate(params, geometry, check=False)

    def _evaluate(self, params, geometry, mueller, check) -> Prediction:
        values, batch = self._resolve(params, check)
        geo = geometry
        for e in self.effects:
            geo = e.transform_geometry(values, geo)
        shape = np.broadcast_shapes(batch + (1,) if batch else (), geo.shape)
        ctx = Context(values, geo, mueller, shape)
        for e in self.effects:
            e.configure(ctx)

        specular = next((e for e in self.effects if isinstance(e, Specular)), None)
        if specular is not None:
            factor = None
            for e in self.effects:
                f = e.specular_factor(ctx)
                if f is not None:
                    factor = f if factor is None else factor * f
            total = specular.specular_lobe(ctx, factor)
            for e in self.effects:
                total = e.modify_specular(ctx, total)
        else:
            total = ctx.zeros()
        lead = (4, 4) if mueller else (4,)
        if total.shape != lead + shape:
            total = np.broadcast_to(total, lead + shape).copy()
        for e in self.effects:
            extra = e.lobe(ctx)
            if isinstance(extra, DepolarizedLobe):
                total = extra.add_to(total, mueller)
            elif extra is not None:
                total += extra
        for e in self.effects:
            total = e.modify_stokes(ctx, total)
        if not geo.all_visible:
            total = np.where(geo.visible, total, 0.0)
        stokes = total[:, 0] if mueller else total
        dop = _dop(stokes)
        for e in self.effects:
            dop = e.modify_dop(ctx, dop)
        return Prediction(stokes=stokes, dop=dop, mueller=total if mueller else None)

    def dop(self, params: dict, geometry: Geometry):
        return self.evaluate(params, geometry).dop


def build_model(spec: str | Model) -> Model:
    return spec if isinstance(spec, Model) else Model.from_string(spec)
