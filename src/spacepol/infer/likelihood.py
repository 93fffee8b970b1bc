"""Likelihood of measured observables given a model (``spacepol.observables``: DOP, BRDF, AoP,
normalised Stokes q/u, normalised Mueller elements).

Each observable has channels, each a vector over the geometries; per channel the noise is the file's
errors or an inferred nuisance level (one per channel group, declared by the observable). Gaussian, or
Student-t with ``robust=True``. The pointwise log-likelihood (one entry per channel and geometry, in
the order of ``observables``) is kept for PSIS-LOO.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp
import numpy as np
from scipy.special import gammaln

from .. import observables as obs
from ..errors import ParameterError
from ..io.measurements import Dataset
from ..physics.arrays import array_module
from ..physics.compiled import Program, set_matrix
from ..physics.model import Model, Prediction
from ..physics.parameter import Parameter
from .likelihood_blocks import (BLOCK_SETS, LARGE_BLOCK_SETS, ONE_BLOCK_NUMBERS, POINTWISE_NUMBERS, SETS_PAYING_A_COMPILATION,
                                SETS_PAYING_THE_SUM, Rows, block_rows, in_cache_sized_chunks, part_slots)


def select_observables(data: Dataset, names=None) -> tuple[list, dict[str, str]]:
    """The Observable objects to fit and ``{observable in the data not fitted: the fitted one holding its
    numbers}``: those named (aliases such as q, u allowed; nothing left out), or by default every observable
    in the data except those a fuller one contains (``observables.default_for``: the Mueller matrix holds
    q, u, DOP and AoP). Unknown, absent or repeated names are one-line errors."""
    available = data.observables
    if not names:
        if not available:
            raise ParameterError(f"{data.source}: no observable to fit (columns of any of "
                                 f"{', '.join(obs.registry.names())})")
        chosen, left_out = obs.default_for(available)
        return [obs.get(n) for n in chosen], left_out
    names = list(names)
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise ParameterError(f"observables {','.join(names)}: {', '.join(repeated)} named twice (each observable counts once)")
    chosen = []
    for name in names:
        o = obs.get(name)
        if not o.present(data):
            raise ParameterError(f"{data.source}: observable '{name}' is not in the data (it has {', '.join(available) or 'none'})")
        if o not in chosen:
            chosen.append(o)
    return chosen, {}


class Likelihood:
    """The log likelihood of a model's predictions for the observables fitted from a data set: one Gaussian (or
    Student-t, ``robust``) term per measured number, with the file's errors or an inferred noise level per channel
    group (the nuisance parameters, ``nuisance``). Observables whose numbers a fitted one already holds are left
    out (``left_out``), so no measured number counts twice. Evaluated for many parameter rows at once."""

    def __init__(self, data: Dataset, model: Model, observables=None, robust: bool = False, nu: float = 4.0):
        self.data, self.model = data, model
        # left_out: observables in the data not fitted because a fitted one holds their numbers
        self.objects, self.left_out = select_observables(data, observables)
        self.observable_names = [o.name for o in self.objects]
        self.needs_mueller = any(o.needs_mueller for o in self.objects)
        self._owner, self._y, self._errors, self._profile = {}, {}, {}, {}
        self.nuisance: list[Parameter] = []
        for o in self.objects:
            observed, errors = o.observed(data), o.errors(data)
            for ch in o.channels:
                self._owner[ch], self._y[ch] = o, np.asarray(observed[ch], float)
                if errors is None:
                    profile = o.noise_profile(ch, data)
                    if profile is not None:
                        self._profile[ch] = np.asarray(profile, float)
                    if o.noise_parameter(ch) not in self.nuisance:
                        self.nuisance.append(o.noise_parameter(ch))
                    continue
                err = np.asarray(errors[ch], float)
                if np.any(err <= 0):
                    raise ParameterError(f"{data.source}: {ch} errors must be > 0 to weigh the fit (found {err.min():g})")
                self._errors[ch] = err
        # channel names, in the order of the pointwise log-likelihood
        self.observables = [ch for o in self.objects for ch in o.channels]
        self.robust, self.nu = robust, float(nu)
        self.geometry = data.geometry
        # observation names that say where a point is (Pareto-k warnings quote them)
        self.labels = [f"{ch}[{i}] (theta_i {data.theta_i[i]:g}, theta_r {data.theta_r[i]:g}, dphi {data.dphi[i]:g} deg)"
                       for ch in self.observables for i in range(len(data))]
        self._jitted, self._program = {}, None  # compiled at the first call, per kind and parameter layout
        # batch sizes a caller will use again and again (emcee's half-ensemble): compiled exactly, not padded
        self.exact_sizes: set[int] = set()
        self._sizes_for, self._sizes = None, []  # ``_compiled_sizes``'s last answer and the exact sizes it was for
        self._sets_in_large_calls = 0  # sets evaluated in calls of at least ``LARGE_BLOCK_SETS`` (``_compiled_sizes``)
        self._sets_in_total_calls = 0  # sets evaluated by ``total`` (``of_matrix``)

    @property
    def numbers_per_set(self) -> int:
        """Values one parameter set's evaluation holds over the geometries: 16 Mueller or 4 Stokes elements each."""
        return (16 if self.needs_mueller else 4) * len(self.data)

    @property
    def batch_sets(self) -> int:
        """How many parameter sets one vectorised evaluation should take: intermediate arrays of
        sets x geometries x (16 Mueller or 4 Stokes) values stay near 4 million numbers (~32 MB); a multiple of the
        compiled block of 16 sets."""
        return max(BLOCK_SETS, 4_000_000 // self.numbers_per_set // BLOCK_SETS * BLOCK_SETS)

    @property
    def compiles_one_block(self) -> bool:
        """Whether calls go through the block of 16 sets (and the caller's ``exact_sizes``) only, however many sets they
        evaluate: where one block's evaluation outweighs a call's fixed cost, a larger block would only add a
        compilation."""
        return BLOCK_SETS * self.numbers_per_set >= ONE_BLOCK_NUMBERS

    @property
    def n_obs(self) -> int:
        """How many measured numbers are fitted (channels x geometries)."""
        return len(self.observables) * len(self.data)

    def observable_of(self, channel: str):
        """The Observable that owns ``channel``."""
        return self._owner[channel]

    def observed(self) -> dict[str, np.ndarray]:
        """The measured numbers per fitted channel."""
        return dict(self._y)

    def predict(self, model_params: dict) -> dict[str, np.ndarray]:
        """The model's prediction of every fitted channel at the data's geometries (uncompiled: for reports)."""
        pred = self.model.evaluate(model_params, self.geometry, mueller=self.needs_mueller, check=False)
        out = {}
        for o in self.objects:
            out.update(o.predict(pred))
        return {ch: out[ch] for ch in self.observables}

    def noise_parameter(self, channel: str) -> str | None:
        """The nuisance parameter holding ``channel``'s noise, or None when the file gives errors."""
        return None if channel in self._errors else self._owner[channel].noise_parameter(channel).name

    def inferred(self, channel: str) -> bool:
        """Whether ``channel``'s noise is a nuisance parameter (the file gives no errors for it)."""
        return channel not in self._errors

    def noise_profile(self, channel: str) -> np.ndarray | None:
        """The factors (N,) on ``channel``'s inferred noise level over the rows (its observable's ``noise_profile``),
        or None where the level is the same on every row."""
        return self._profile.get(channel)

    def scale(self, channel: str, params: dict | None = None):
        """The channel's noise: the file's errors (N,), or the nuisance level per parameter set (P, 1), times
        the observable's profile over the rows (P, N) where it has one (AoP's 1 / DOP)."""
        if channel in self._errors:
            return self._errors[channel]
        level = np.asarray(params[self.noise_parameter(channel)])[:, None]
        return level * self._profile[channel] if channel in self._profile else level

    def residual(self, channel: str, mu):
        """Measured minus predicted in the space where the channel's noise is Gaussian."""
        return self._owner[channel].residual(channel, self._y[channel], mu, self.inferred(channel))

    def standardise(self, channel: str, mu, scale):
        """Residuals of prediction ``mu`` in units of the noise ``scale``."""
        return self.residual(channel, mu) / scale

    def replicate(self, channel: str, mu, scale, rng: np.random.Generator):
        """A replicated measurement of ``channel`` (posterior predictive): prediction ``mu`` plus noise ``scale``."""
        return self._owner[channel].replicate(channel, mu, scale, self.inferred(channel), rng)

    def pointwise(self, params: dict) -> np.ndarray:
        """Log-likelihood per observation, shape (P, n_obs), for P parameter sets (model and noise parameters)."""
        return self._call(0, params)

    def total(self, params: dict) -> np.ndarray:
        """Log-likelihood per parameter set, (P,): the pointwise sum, fused (nothing of size n_obs is kept); on a
        large data set (``compiles_one_block``), where a call's block holds at most ``POINTWISE_NUMBERS`` numbers,
        the sum of ``pointwise``, so that a model compiles one likelihood program, not two (a call of either costs
        far less than a compilation, and every model diagnose refits needs the pointwise one too), until the sets
        evaluated here would have paid for the fused program's compilation (``SETS_PAYING_THE_SUM``)."""
        return self._call(1, params)

    def expect_sets(self, n_sets: int) -> None:
        """A caller about to evaluate ``n_sets`` parameter sets by ``total`` (a sampler's whole run): counted as
        evaluated, so that a large likelihood compiles its fused program at once where they would pay for it
        (``SETS_PAYING_THE_SUM``) instead of reaching it through the pointwise program."""
        self._sets_in_total_calls += n_sets

    @property
    def profilable(self) -> list[str]:
        """The inferred noise levels whose conditional maximum is closed-form (Gaussian noise: the RMS of the
        scaled residuals of their channels); none under the Student-t likelihood."""
        return [] if self.robust else [p.name for p in self.nuisance]

    def profiled(self, model_params: dict, levels: tuple) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """(log-likelihood per parameter set (P,), {level: (P,) values}) with each noise level in ``levels``
        (((name, lower, upper), ...), from ``profilable``) at its conditional maximum: the RMS of its channels'
        residuals over their noise profiles, clipped to [lower, upper] (the log-likelihood is unimodal in each
        level, so the clipped value is the maximum inside the bounds)."""
        out = self._call(2, model_params, tuple(levels))
        return out[:, 0], {name: out[:, 1 + j] for j, (name, _, _) in enumerate(levels)}

    def _call(self, which: int, params: dict, levels: tuple = ()) -> np.ndarray:
        """Parameter sets go in as one (P, K) matrix (one argument: a JAX call with a dict of arrays spends
        more on argument handling than a small likelihood itself takes); scalars are compiled in."""
        columns, scalars, n_sets = [], {}, 0
        for name, v in params.items():
            if np.ndim(v) == 0:
                scalars[name] = float(v)
            else:
                v = np.asarray(v, float).reshape(-1)
                columns.append((name, v))
                n_sets = max(n_sets, v.size)
        names = tuple(n for n, _ in columns)
        matrix = set_matrix([v for _, v in columns], n_sets) if n_sets else None
        return self.of_matrix(which, names, tuple(sorted(scalars.items())), matrix, levels)

    def of_matrix(self, which: int, names: tuple, scalars: tuple, matrix, levels: tuple = ()) -> np.ndarray:
        """``_call`` with the parameter sets already one (P, len(names)) matrix (None: no column) and the held values
        ``scalars`` ((name, value), ... sorted by name): what a sampler's every step calls, without the dict."""
        n_sets = 0 if matrix is None else len(matrix)
        if n_sets >= LARGE_BLOCK_SETS:
            self._sets_in_large_calls += n_sets
        sizes = self._compiled_sizes()
        rows = block_rows(n_sets, sizes)
        # ``total`` of a large likelihood: the pointwise program, summed (see ``total``)
        if which == 1:
            self._sets_in_total_calls += n_sets
        summed = (which == 1 and self.compiles_one_block and rows * self.numbers_per_set <= POINTWISE_NUMBERS
                  and self._sets_in_total_calls <= SETS_PAYING_THE_SUM)
        key = (0 if summed else which, names, scalars, levels)
        if key not in self._jitted:
            self._jitted[key] = self._compile(*key)
        if not n_sets:
            out = np.asarray(self._jitted[key](np.zeros((1, 0))))[0]
            return out.sum(axis=-1) if summed else out
        out = []
        for i in range(0, n_sets, rows):
            block = matrix[i : i + rows]
            n = len(block)
            # the last block of a long call is padded to the others' size (compiled already), not to a size of its own
            size = rows if rows in sizes and i else next((s for s in sizes if s >= n), n)
            if size > n:  # padded with the last set (a valid one)
                block = np.concatenate([block, np.repeat(block[-1:], size - n, axis=0)])
            out.append(np.asarray(self._jitted[key](block))[:n])
        out = out[0] if len(out) == 1 else np.concatenate(out, axis=0)
        return out.sum(axis=-1) if summed else out

    def _compiled_sizes(self) -> list[int]:
        """The block sizes calls are padded to: 16 sets, the callers' exact sizes, and 256 sets once the sets this
        likelihood evaluated in calls of that size would have paid for its compilation (never on a large data set:
        ``compiles_one_block``). Kept until these change: a sampler calls this at every step."""
        large = not self.compiles_one_block and self._sets_in_large_calls >= SETS_PAYING_A_COMPILATION
        state = (frozenset(self.exact_sizes), large)
        if self._sizes_for != state:
            self._sizes_for, self._sizes = state, sorted({BLOCK_SETS, *([LARGE_BLOCK_SETS] if large else []), *state[0]})
        return self._sizes

    def _compile(self, which: int, names: tuple, scalars: tuple, levels: tuple = ()):
        return jax.jit(self.function(which, names, scalars, levels))

    def function(self, which: int, names: tuple, scalars: tuple, levels: tuple = ()):
        """The pure JAX function (not compiled) of a (P, len(names)) parameter matrix: the pointwise
        log-likelihood (``which`` 0), its sum per set (1), or that sum with the noise ``levels`` profiled
        (2: (P, 1 + len(levels)), the sum and the levels; ``profiled``); ``scalars``: ((name, value), ...)
        held fixed. Gradient samplers and optimizers compose it with their own transforms and differentiate it."""
        if self._program is None:
            self._program = Program(self.model, self.geometry, self.needs_mueller,
                                    up_to_scale=all(o.scale_free for o in self.objects), fold=True)
        program, fixed = self._program, dict(scalars)
        model_names = {p.name for p in self.model.parameters}
        mueller = self.needs_mueller
        if levels and self.robust:
            raise ValueError("noise levels are profiled under the Gaussian likelihood only (robust=False)")
        profiled_names = [name for name, _, _ in levels]
        groups = self._channel_groups()
        # one wavelength at a time (``Program.part``), each in its mirror fold's slots where the program folds
        parts = [part_slots(self._y, self._errors, self._profile, program, j, mueller) for j in range(len(program.parts))]

        def channel_blocks(matrix):
            """(per slot of every part, the log-likelihood of each channel group, (channels, P, rows) each, in
            ``self.observables``' order, 0 where a slot holds no row; the profiled levels' values, (P,) each, in
            ``levels``' order)."""
            values = {**fixed, **{n: matrix[:, j, None] for j, n in enumerate(names)}}
            model_values = {k: v for k, v in values.items() if k in model_names}
            slots, resids = [], []
            for j, (part_slots, _) in enumerate(parts):
                total, dop = program.part(j, model_values, program.inputs)
                slots += part_slots
                resids += [self._residuals(groups, total, dop, rows) for rows in part_slots]
            profiled = self._profiled(levels, groups, resids, slots, matrix.shape[0]) if levels else []
            values.update({name: level[:, None] for name, level in zip(profiled_names, profiled)})
            blocks = [self._log_densities(groups, values, slot_resids, rows, matrix.shape[0])
                      for rows, slot_resids in zip(slots, resids)]
            return blocks, profiled

        def pointwise(matrix):
            # per group (channels, P, N): each part's slots side by side, its rows picked from them, the parts side by
            # side in the data's order; then (P, channels x N): each channel's N values in a row, in ``observables``' order
            blocks, at = channel_blocks(matrix)[0], 0
            per_part = []
            for part_slots, positions in parts:
                mine, at = blocks[at : at + len(part_slots)], at + len(part_slots)
                joined = [jnp.concatenate(group, axis=-1) for group in zip(*mine)]
                per_part.append(joined if positions is None else [b[..., positions] for b in joined])
            groups_rows = [jnp.concatenate(group, axis=-1) for group in zip(*per_part)]
            if program.inverse is not None:
                groups_rows = [b[..., program.inverse] for b in groups_rows]
            return jnp.concatenate([jnp.moveaxis(b, 0, 1).reshape(matrix.shape[0], -1) for b in groups_rows], axis=-1)

        def summed(matrix):
            # the single channels added element by element, then one sum over the rows: one reduction (summed from a
            # concatenation, XLA stored every Mueller element and reduced each channel in a partitioned loop of
            # its own: 32 loops and their hand-overs between threads per call, 16 of them reductions)
            blocks, profiled = channel_blocks(matrix)
            value = 0.0
            for slot_blocks in blocks:
                single = [b[0] for b in slot_blocks if len(b) == 1]
                value = value + (sum(single).sum(axis=-1) if single else 0.0)
                value = value + sum(b.sum(axis=(0, 2)) for b in slot_blocks if len(b) > 1)
            return jnp.stack([value, *profiled], axis=-1) if levels else value

        return pointwise if which == 0 else in_cache_sized_chunks(summed, self.numbers_per_set)

    def _residuals(self, groups, total, dop, rows: Rows) -> list:
        """Each channel group's residuals at ``rows`` from the model's (total, dop) there, (channels, P or 1, N or 1),
        in ``self.observables``' order."""
        prediction = Prediction.from_total(total if rows.signs is None else total * rows.signs, dop, self.needs_mueller)
        out, predicted = [], {}
        for o, channels in groups:
            if len(channels) > 1:  # one array for the group (``Observable.predict_stacked``)
                observed = jnp.stack([rows.y[ch] for ch in channels])[:, None, :]
                out.append(o.residual(channels[0], observed, o.predict_stacked(prediction), self.inferred(channels[0])))
                continue
            ch = channels[0]
            if ch not in predicted:
                predicted.update(o.predict(prediction))
            out.append(o.residual(ch, rows.y[ch], predicted[ch], self.inferred(ch))[None])
        return out

    def _log_densities(self, groups, values: dict, resids: list, rows: Rows, n_sets: int) -> list:
        """Each channel group's log-likelihood at ``rows``, (channels, P, rows), 0 where a slot holds no row."""
        out = []
        for (_, channels), resid in zip(groups, resids):
            # each channel's noise as (P or 1, N or 1), stacked over the group's channels
            scales = [jnp.asarray(rows.errors[ch] if ch in rows.errors
                                  else values[self.noise_parameter(ch)] * rows.profiles.get(ch, 1.0)) for ch in channels]
            scales = [jnp.broadcast_to(sc, jnp.broadcast_shapes(sc.shape, (1, 1))) for sc in scales]
            lp = self._logpdf(channels[0], resid, jnp.stack(jnp.broadcast_arrays(*scales)))
            lp = jnp.broadcast_to(lp, (len(channels), n_sets, rows.size))
            out.append(lp if rows.valid is None else jnp.where(rows.valid, lp, 0.0))
        return out

    def _profiled(self, levels, groups, resids, slots, n_sets) -> list:
        """Each level of ``levels`` at its conditional maximum (the RMS of its channels' scaled residuals over every
        slot's rows)."""
        out = []
        for name, lower, upper in levels:
            squares, count = 0.0, 0
            for rows, slot_resids in zip(slots, resids):
                held = rows.size if rows.valid is None else int(np.sum(np.asarray(rows.valid)))
                for (_, channels), resid in zip(groups, slot_resids):
                    for c, ch in enumerate(channels):
                        if ch not in rows.errors and self.noise_parameter(ch) == name:
                            z2 = jnp.broadcast_to(resid[c] / rows.profiles.get(ch, 1.0), (n_sets, rows.size)) ** 2
                            squares = squares + jnp.sum(z2 if rows.valid is None else jnp.where(rows.valid, z2, 0.0), axis=-1)
                            count += held
            out.append(jnp.clip(jnp.sqrt(squares / count), lower, upper))
        return out

    def _channel_groups(self) -> list[tuple]:
        """[(observable, its channels)]: an observable's channels as one group where it predicts them as one array
        (``Observable.predict_stacked``) and its noise is of one kind for all of them (all the file's errors, or all
        inferred); else each channel alone. In ``observables``' order."""
        out = []
        for o in self.objects:
            kinds = {self.inferred(ch) for ch in o.channels}
            stacked = len(o.channels) > 1 and len(kinds) == 1 and type(o).predict_stacked is not obs.Observable.predict_stacked
            out.extend([(o, tuple(o.channels))] if stacked else [(o, (ch,)) for ch in o.channels])
        return out

    def _logpdf(self, channel, resid, scale):
        if not self.robust:
            return self._owner[channel].log_density(resid, scale)
        xp = array_module(resid, scale)
        nu = self.nu
        const = gammaln((nu + 1) / 2) - gammaln(nu / 2) - 0.5 * math.log(nu * math.pi)
        return const - xp.log(scale) - 0.5 * (nu + 1) * xp.log1p((resid / scale) ** 2 / nu)
