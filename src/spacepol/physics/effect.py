"""The Effect interface: one physical ingredient of the pBRDF, composable with ``+``. An effect declares the
parameters it owns, the effects it needs or excludes, what model criticism needs to know about it (slot, twins,
neutral values, ...), and takes part in the evaluation through hooks (geometry, configuration, the specular
factor and lobe, an additive lobe, the total Stokes vector or Mueller matrix, the measured DOP).

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import jax.numpy as jnp
import numpy as np

from .geometry import Geometry
from .parameter import Parameter


@dataclass
class Context:
    """Everything an effect may read during one evaluation."""

    params: dict
    geometry: Geometry
    mueller: bool
    shape: tuple
    facet_shape: str = "beckmann"  # or "ggx"
    anisotropic_slopes: tuple | None = None  # (sigma_x, sigma_y, psi_deg)
    fresnel_amplitudes: Callable | None = None  # (cos, sin2) -> (r_s, r_p); None = bulk N = n + ik
    up_to_scale: bool = False  # the caller needs the total only up to a positive factor per element
    notes: dict = field(default_factory=dict)

    def __getitem__(self, name):
        return self.params[name]

    def zeros(self):
        """An all-zero total of the model's shape: (4, 4, ...) for Mueller matrices, (4, ...) for Stokes vectors."""
        lead = (4, 4) if self.mueller else (4,)
        return jnp.zeros(lead + self.shape)

    def depolarized(self, value) -> "DepolarizedLobe":
        """A lobe whose light is unpolarized with intensity ``value`` (Mueller diag(1,0,0,0))."""
        return DepolarizedLobe(value)

    def first_column_times_row(self, column, row):
        """Lobe of a Mueller matrix column (x) row: ``row`` is applied to the incident Stokes vector.

        Used by lobes that depolarize inside the material: only how much intensity enters
        (``row``, its first element for unpolarized light) and the state it leaves in (``column``) matter.
        """
        # the vectors are stacked first and multiplied as whole arrays: a compiled program then computes each
        # of their entries once, where one product per element made it compute them again in every element
        # one shape for both: with n held fixed (a scalar) the row through the interface has no axis of sets
        entries = jnp.broadcast_arrays(*column, *row)
        column, row = jnp.stack(entries[: len(column)]), jnp.stack(entries[len(column):])
        if self.mueller:
            return column[:, None] * row[None, :]
        return column * row[0]


@dataclass
class Ratio:
    """A Stokes vector given as its rows (S0, S1, S2, S3) over a ``denominator`` > 0 per element, returned
    only where ``ctx.up_to_scale``: the rest of the total is then multiplied by the denominator instead of
    divided (``compiled.evaluate_values``). For the paper's DOP this removes the Fresnel divisions (5 divisions
    per evaluation -> 1).

    ``polarized``: where known in closed form, a value whose absolute value is the polarized part
    sqrt(S1^2 + S2^2 + S3^2) of the rows (a lobe polarized along one unit direction: the specular lobe's S1
    in the facet's basis); unpolarized lobes keep it, a polarized one drops it. It saves the DOP's square root
    (paper's DOP: 2 square roots, 1 division and an exp per evaluation)."""

    rows: list
    denominator: jnp.ndarray
    polarized: jnp.ndarray | None = None

    def plus(self, lobe) -> "Ratio":
        """This total plus a lobe of true values (an array (4, ...) or a DepolarizedLobe)."""
        if isinstance(lobe, DepolarizedLobe):
            return Ratio([self.rows[0] + lobe.intensity * self.denominator, *self.rows[1:]], self.denominator,
                         self.polarized)
        return Ratio([row + lobe[j] * self.denominator for j, row in enumerate(self.rows)], self.denominator)

    def broadcast_rows(self, shape) -> list:
        """Each row of the numerator broadcast to ``shape``."""
        return [jnp.broadcast_to(row, shape) for row in self.rows]

    def divided(self, shape):
        """The true Stokes vector, (4, *shape)."""
        return jnp.stack(self.broadcast_rows(shape)) / self.denominator


@dataclass
class DepolarizedLobe:
    """An additive lobe of unpolarized light: only S0 (M00) is non-zero, so only it is stored."""

    intensity: jnp.ndarray

    def add_to(self, total, mueller: bool):
        # added through a one-hot (4, 4) or (4,) pattern, not written into M00 in place: an in-place update
        # made XLA copy every element of the total out again for the likelihood's reductions
        """``total`` plus this lobe's intensity in S0 (M00)."""
        pattern = np.zeros((4, 4) if mueller else (4,))
        pattern.flat[0] = 1.0
        return total + jnp.asarray(self.intensity) * pattern.reshape(pattern.shape + (1,) * (jnp.ndim(total) - pattern.ndim))


class Effect:
    """Base class of all effects.  Subclasses set the class attributes and override hooks.

    Besides its physics an effect carries what model criticism needs to know about it, so that a
    plug-in takes part on equal terms with the built-ins (nothing in diagnose, the optimiser or the
    identifiability report names an effect):

    * ``slot``: the role it plays ("shadowing", "body", "facets"), or None for a pure addition;
      effects of one slot can replace each other ("replace shadowing by smith");
    * ``substitutes``: other effects it may replace besides its slot's members (a volume lobe for a body term);
    * ``removable``: "remove E" is a sensible change (a shadowing term, a diffuse lobe);
    * ``essential``: the lobe the model is built on (``specular``): never removed or swapped for an
      addition, though it has no slot;
    * ``twins``: {other effect: the measurement that separates them} for effects that predict the
      same thing on some data (both are then always refitted, and a tie is reported with it);
    * ``separated_by``: {twin: observable names}, where fitting any of these observables tells the two apart
      (the full Mueller matrix separates an analyser from depolarized light): on such data the twin is
      refitted only if its own screening earns it;
    * ``neutral``: parameter values at which the effect changes nothing (where the optimiser starts
      it when it is added to a fitted model);
    * ``splits``: {own parameter: model parameter it refines} (anisotropy's sigma_x starts at sigma);
    * ``branches``: parameter subsets worth a separate optimiser search (a dielectric's k = 0 is a
      sliver of the k prior that a global search otherwise misses);
    * ``mirror_symmetric``: it keeps an isotropic sample's mirror symmetry, M(-dphi) = D M(dphi) D (``physics.mirror``):
      the likelihood of a model of such effects evaluates it once per mirror pair of the data; False unless it says so;
    * ``intensity``: the parameter that scales this effect's lobe (DOP, a ratio of intensities,
      measures only ratios of such parameters: the identifiability report says so);
    * ``applicable(data)``: why the effect cannot be used with these data (None if it can);
    * ``identifiable(values)``: the parameters in a form the data can identify (label swaps removed).
    """

    name: str = ""
    parameters: tuple[Parameter, ...] = ()
    requires: tuple[str, ...] = ()  # effect names that must be in the model too
    excludes: tuple[str, ...] = ()
    removes: tuple[str, ...] = ()  # parameters of other effects this one makes unused
    reciprocal: bool = True  # does it keep M(i -> r) = Q M(r -> i)^T Q ?
    # does it keep M(-dphi) = D M(dphi) D (an isotropic sample's mirror image, ``physics.mirror``)? A plug-in must say
    # so itself: the likelihood then evaluates the model once per mirror pair of the data
    mirror_symmetric: bool = False
    description: str = ""
    slot: str | None = None
    substitutes: tuple[str, ...] = ()
    removable: bool = False
    essential: bool = False
    twins: dict = {}
    separated_by: dict = {}
    neutral: dict = {}
    splits: dict = {}
    branches: tuple = ()
    intensity: str | None = None
    # values the hidden-effect suite hides in its renders (a small and a large one), each strictly inside its prior: a
    # truth on a bound lies outside every central interval of a posterior that cannot cross the bound
    hidden_values: tuple = ()

    def applicable(self, data) -> str | None:
        """None when the effect can be used with ``data``; else the reason, in words."""
        return None

    def identifiable(self, values: dict) -> dict:
        """{parameter: array} in a canonical form free of label swaps (default: as is)."""
        return values

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.__dict__.get("description"):  # one text for help(), docs and `effects`: the summary, then the physics
            own = (cls.__dict__.get("__doc__") or "").strip()
            cls.__doc__ = f"{own}\n\n{cls.description}" if own else f"The ``{cls.name}`` effect. {cls.description}"

    # lmfit-style composition: effect + effect -> Model. model.py sets _model_type when it defines Model, so this
    # module needs no import of the one that builds on it (the physics package imports both)
    _model_type = None

    def __add__(self, other):
        return Effect._model_type([self]) + other

    def __repr__(self):
        return f"<effect {self.name}>"

    def transform_geometry(self, params, geometry: Geometry) -> Geometry:
        """Hook: the geometry the other effects see (e.g. an angle offset); default unchanged."""
        return geometry

    def configure(self, ctx: Context) -> None:
        """Hook: set what the other stages read from the context (slope distribution, Fresnel amplitudes) before any
        lobe."""
        pass

    def specular_factor(self, ctx: Context):
        """Hook: a factor on the specular lobe (shadowing-masking); None for none."""
        return None

    def modify_specular(self, ctx: Context, lobe):
        """Hook: the specular lobe changed (e.g. depolarized); default unchanged."""
        return lobe

    def lobe(self, ctx: Context):
        """Hook: an additive lobe (a Stokes vector or Mueller matrix array, or a DepolarizedLobe); None for none."""
        return None

    def modify_stokes(self, ctx: Context, total):
        """Hook: the total Stokes vector or Mueller matrix changed (e.g. extinction); default unchanged."""
        return total

    def modify_dop(self, ctx: Context, dop):
        """Hook: the measured DOP changed (e.g. an instrument bias); default unchanged."""
        return dop


_STAGES = {"lobe", "specular_factor", "modify_specular", "modify_stokes", "modify_dop"}


def effect(name: str, *, stage: str, parameters=(), requires=(), description: str = "", reciprocal: bool = True,
           slot: str | None = None, removable: bool = False, twins=None, neutral=None, separated_by=None,
           mirror_symmetric: bool = False):
    """Decorator that turns a function into an effect class.

    ``stage`` names the hook the function implements; it is called as ``fn(ctx, ...)`` with
    the lobe/total/dop as second argument where the hook has one, and the effect's own
    parameters as keyword arguments::

        @effect("sheen", stage="lobe", parameters=[Parameter("a", "", Uniform(0, 1), 0.1, "...")])
        def sheen(ctx, a):
            return ctx.depolarized(a * ctx.geometry.cos_tr / jnp.pi)
    """
    if stage not in _STAGES:
        raise ValueError(f"effect '{name}': unknown stage '{stage}' (choose from {sorted(_STAGES)})")

    def wrap(fn):
        own = tuple(parameters)

        def hook(self, ctx, *args):
            kwargs = {p.name: ctx.params[p.name] for p in own}
            return fn(ctx, *args, **kwargs)

        attrs = {
            "name": name,
            "parameters": own,
            "requires": tuple(requires),
            "description": description or (fn.__doc__ or "").strip(),
            "reciprocal": reciprocal,
            "mirror_symmetric": mirror_symmetric,
            "slot": slot,
            "removable": removable,
            "twins": dict(twins or {}),
            "separated_by": {twin: tuple(names) for twin, names in (separated_by or {}).items()},
            "neutral": dict(neutral or {}),
            stage: hook,
            "__module__": fn.__module__,
            "__doc__": fn.__doc__,
        }
        return type(fn.__name__, (Effect,), attrs)

    return wrap
