"""The model's evaluation as one JAX function, and what it takes to make XLA run it fast on a CPU.

``evaluate_values`` calls the effects' hooks in their order (``effect``'s docstring) on traced values;
``jitted`` compiles it once per model structure (built-in effects by class, plug-ins by instance), output
kind and fixed values, shared by every Model built from the same effects; ``Program`` is the evaluation
over all rows of a data set for a Model or a SpectralModel (one part per wavelength), for callers that
compile more around it (the likelihood). Parameter sets are padded to ``bucket`` sizes so the walkers,
batches and remainders of an inversion do not each compile a program.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from .._runtime import ensure_double_precision
from .arrays import array_module
from .effects.specular import Specular
from .effect import Context, DepolarizedLobe, Effect, Ratio
from .geometry import Geometry
from .mirror import MirrorFold
from .plugin_guard import is_plugin

_JITTED: dict = {}


def degree_of_polarization(stokes, polarized=None):
    """|S_pol| / S0 (0 where S0 = 0): a (4, ...) numpy or JAX array, or its four rows; ``polarized``: a value
    whose absolute value is |S_pol| where the caller knows one (``effect.Ratio.polarized``)."""
    xp = array_module(*stokes)
    s0 = stokes[0]
    if polarized is not None:
        pol = xp.abs(polarized)
    else:
        pol2 = stokes[1] ** 2 + stokes[2] ** 2 + stokes[3] ** 2
        nonzero = pol2 > 0  # sqrt kept off 0, where its derivative is infinite (unpolarized retro-reflection)
        pol = xp.where(nonzero, xp.sqrt(xp.where(nonzero, pol2, 1.0)), 0.0)
    lit = s0 > 0
    # |S| <= S0 holds for every lobe; rounding may push a ratio an ulp above 1.
    return xp.where(lit, xp.minimum(pol / xp.where(lit, s0, 1.0), 1.0), 0.0)


def bucket(n_sets: int) -> int:
    """Parameter sets are padded to a power of two: one compiled program per octave of batch sizes
    (a compilation costs more than the padded sets do; ``Likelihood.batch_sets`` is one too)."""
    return 1 << max(0, (n_sets - 1).bit_length())


def packed(values: dict, n_sets: int) -> np.ndarray:
    """The given values as one array, columns in ``values``' order: (bucket(n_sets), K) for parameter sets
    ((n_sets, 1) arrays; a scalar is repeated), padded by repeating the last set (always a valid one), or (K,)
    for scalars alone. One argument: the call then hands one buffer to the program instead of one per
    parameter, a noticeable share of a small call."""
    if not n_sets:
        return np.array([float(v) for v in values.values()])
    columns = set_matrix(values.values(), n_sets)
    extra = bucket(n_sets) - n_sets
    return np.pad(columns, ((0, extra), (0, 0)), mode="edge") if extra else columns


def set_matrix(values, n_sets: int) -> np.ndarray:
    """(n_sets, K): one column per value, each n_sets values or one shared by every set (a scalar, a length-1
    array); stacked directly in the common case of one value per set for every column (as a sampler calls)."""
    flat = [np.ravel(v) for v in values]
    if all(v.size == n_sets for v in flat):
        return np.column_stack(flat)
    return np.column_stack([np.broadcast_to(v, (n_sets,)) for v in flat])


def unpacked(names: tuple, matrix) -> dict:
    """``packed``'s inverse inside the program: (P, 1) columns, or scalars."""
    if jnp.ndim(matrix) == 1:
        return {name: matrix[j] for j, name in enumerate(names)}
    return {name: matrix[:, j, None] for j, name in enumerate(names)}


def batch_of(values: dict) -> tuple:
    """(P,) for values holding P parameter sets as (P, 1) arrays, () for scalars only."""
    sizes = [np.shape(v)[0] for v in values.values() if np.ndim(v) == 2]
    return (max(sizes),) if sizes else ()


def once(value, shape):
    """A hook's output that does not vary over parameter sets (the paper's shadowing at fixed constants)
    computed once: without the barrier XLA fuses it into every (set, geometry) element that uses it.
    Checked on the `paper` DOP program: XLA's CPU compiler removes the barrier, and the compiled
    fusions are the same without it (the shadowing is its own 84-element fusion either way: a value broadcast
    over the sets is not fused with its expensive producer); kept for other backends, not measured there."""
    if value is None or len(shape) < 2 or np.ndim(value) == 0 or np.shape(value)[-2:-1] == shape[-2:-1]:
        return value
    return jax.lax.optimization_barrier(value)


def _overrides(effect, hook: str) -> bool:
    return getattr(type(effect), hook) is not getattr(Effect, hook)


def evaluate_values(effects, values: dict, batch: tuple, geometry: Geometry, mueller: bool, up_to_scale: bool = False):
    """The effects' hooks in their order: (Stokes (4, ...) or Mueller (4, 4, ...) total, measured DOP).

    ``up_to_scale``: the caller uses the total only through ratios of its elements (the DOP, normalised
    Stokes parameters), so it may come back multiplied by a positive number per (set, geometry) element: the
    specular lobe then keeps its Fresnel denominator aside (``effect.Ratio``) until a hook that is not the
    base class's needs the true values. Measured on the paper's DOP, 4,096 x 84, interleaved in one process:
    507 -> 667-758 M evaluations/s (one fused loop with 3 square roots, 1 division and 1 exp per element);
    without the DOP's own square root (``Ratio.polarized``) 1.09x on one core (XLA single-threaded, 7 rounds),
    1.03-1.06x on two."""
    geo = geometry
    for e in effects:
        geo = e.transform_geometry(values, geo)
    shape = np.broadcast_shapes(batch + (1,) if batch else (), geo.shape)
    ctx = Context(values, geo, mueller, shape, up_to_scale=up_to_scale and not mueller)
    for e in effects:
        e.configure(ctx)

    specular = next((e for e in effects if isinstance(e, Specular)), None)
    if specular is not None:
        factor = None
        for e in effects:
            f = once(e.specular_factor(ctx), shape)
            if f is not None:
                factor = f if factor is None else factor * f
        total = specular.specular_lobe(ctx, factor)
        for e in effects:
            if isinstance(total, Ratio) and _overrides(e, "modify_specular"):
                total = total.divided(shape)
            total = e.modify_specular(ctx, total)
    else:
        total = ctx.zeros()
    lead = (4, 4) if mueller else (4,)
    if not isinstance(total, Ratio):
        total = jnp.broadcast_to(total, lead + shape)
    for e in effects:
        extra = e.lobe(ctx)
        if extra is None:
            continue
        if isinstance(extra, DepolarizedLobe):
            extra = DepolarizedLobe(once(extra.intensity, shape))
        if isinstance(total, Ratio):
            total = total.plus(extra)
        elif isinstance(extra, DepolarizedLobe):
            total = extra.add_to(total, mueller)
        else:
            total = total + extra
    for e in effects:
        if isinstance(total, Ratio) and _overrides(e, "modify_stokes"):
            total = total.divided(shape)
        total = e.modify_stokes(ctx, total)
    if isinstance(total, Ratio):  # the rows stay separate up to the DOP (a stacked array is not fused with it)
        rows = total.broadcast_rows(shape)
        polarized = None if total.polarized is None else jnp.broadcast_to(total.polarized, shape)
        if not geo.all_visible:
            rows = [jnp.where(geo.visible, row, 0.0) for row in rows]
            polarized = None if polarized is None else jnp.where(geo.visible, polarized, 0.0)
        dop = degree_of_polarization(rows, polarized)
        total = jnp.stack(rows)
    else:
        if not geo.all_visible:
            total = jnp.where(geo.visible, total, 0.0)
        dop = degree_of_polarization(total[:, 0] if mueller else total)
    for e in effects:
        dop = e.modify_dop(ctx, dop)
    return total, dop


def jitted(effects, names: tuple, fixed: dict, mueller: bool, all_visible: bool, dop_only: bool = False):
    """The compiled evaluation ``run(packed(traced values), geometry.device_terms()) -> (total, dop)``, or
    ``-> (dop,)`` with ``dop_only`` (the Stokes vector then stays inside the fused program: for the paper's DOP,
    4 x 4,096 x 84, writing it out cost 40 % of the evaluation); ``fixed`` values (parameters nobody set) are compiled
    in as constants; ``names``: the traced parameters, in the packed columns' order."""
    key = (tuple(e if is_plugin(e) else type(e) for e in effects), names, mueller, tuple(sorted(fixed.items())),
           all_visible, dop_only)
    if key not in _JITTED:
        def run(matrix, terms):
            traced = unpacked(names, matrix)
            total, dop = evaluate_values(effects, {**fixed, **traced}, batch_of(traced),
                                         Geometry.from_terms(terms, all_visible), mueller, up_to_scale=dop_only)
            return (dop,) if dop_only else (total, dop)

        _JITTED[key] = jax.jit(run)
    return _JITTED[key]


class Program:
    """A Model's or SpectralModel's evaluation over all rows of one geometry as a pure function of traced
    parameter values: ``program(values, program.inputs) -> (total, dop)`` in the rows' order; with
    ``up_to_scale`` the total is right only up to a positive factor per element (``evaluate_values``), for
    callers that use nothing but ratios of its elements. With ``fold``, rows that are each other's mirror images
    are evaluated once (``physics.mirror``)."""

    def __init__(self, model, geometry: Geometry, mueller: bool, up_to_scale: bool = False, fold: bool = False):
        ensure_double_precision()
        inner = model.inner
        self.effects, self.defaults, self.mueller, self.up_to_scale = inner.effects, inner.defaults(), mueller, up_to_scale
        self.parts = model.parts(geometry)  # [(rows, sub-geometry, values -> the inner model's values)]
        self.size = geometry.size
        order = np.concatenate([np.arange(geometry.size)[rows] for rows, _, _ in self.parts])
        self.inverse = None if np.array_equal(order, np.arange(geometry.size)) else jnp.asarray(np.argsort(order))
        symmetric = fold and all(e.mirror_symmetric for e in self.effects)
        # per part, its mirror fold (None: every row evaluated; ``part`` then gives every row)
        self.folds = [MirrorFold.of(sub) if symmetric else None for _, sub, _ in self.parts]
        self.inputs = [(sub if f is None else f.geometry).device_terms() for (_, sub, _), f in zip(self.parts, self.folds)]

    def part_rows(self, j: int) -> np.ndarray:
        """The rows of the data (indices) that part ``j`` evaluates, in the order of its output."""
        return np.arange(self.size)[self.parts[j][0]]

    def part(self, j: int, values: dict, inputs):
        """Part ``j`` alone (one wavelength of a SpectralModel): (total, dop) at ``part_rows(j)``, or at its mirror
        fold's geometries where it has one (``folds[j]``: ``fold`` and every effect ``mirror_symmetric``). A caller that
        reduces over rows (the likelihood's sum) takes the parts one by one: concatenated, XLA on a CPU fused the
        four wavelengths' evaluations into one loop over all rows and ran at half their separate speed."""
        (_, sub, inner_values), terms, fold = self.parts[j], inputs[j], self.folds[j]
        return evaluate_values(self.effects, {**self.defaults, **inner_values(values)}, batch_of(values),
                               Geometry.from_terms(terms, (sub if fold is None else fold.geometry).all_visible),
                               self.mueller, self.up_to_scale)

    def __call__(self, values: dict, inputs):
        outputs = [self.part(j, values, inputs) if f is None else f.unfold(*self.part(j, values, inputs), self.mueller)
                   for j, f in enumerate(self.folds)]
        if len(outputs) == 1:
            return outputs[0]
        total = jnp.concatenate([t for t, _ in outputs], axis=-1)
        dop = jnp.concatenate([d for _, d in outputs], axis=-1)
        if self.inverse is not None:
            total, dop = total[..., self.inverse], dop[..., self.inverse]
        return total, dop
