"""Likelihood of measured observables given a model (``spacepol.observables``: DOP, BRDF, AoP,
normalised Stokes q/u, normalised Mueller elements).

Each observable has channels, each a vector over the geometries; per channel the noise is the file's
errors or an inferred nuisance level (one per channel group, declared by the observable). Gaussian, or
Student-t with ``robust=True``. The pointwise log-likelihood (one entry per channel and geometry, in
the order of ``observables``) is kept for PSIS-LOO.

The log-likelihood is one compiled JAX function of the parameter sets: the model's evaluation, the
observables' predictions, residuals and densities fused, so no Mueller matrix or residual array of
sets x geometries is written to memory when only the sum per set is wanted (``total``, what the samplers
and optimizers call).
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
from ..observables.base import array_module
from ..physics.compiled import Program, padded
from ..physics.model import Model, Prediction
from ..physics.parameter import Parameter

def select_observables(data: Dataset, names=None) -> tuple[list, dict[str, str]]:
    """The Observable objects to fit and ``{observable in the data not fitted: the fitted one holding its
    numbers}``: those named (aliases such as q, u allowed; nothing left out), or by default every observable
    in the data except those a fuller one contains (``observables.default_for``: the Mueller matrix holds
    q, u, DOP and AoP). Unknown, absent or repeated names are one-line errors."""
    available = [o.name for o in obs.OBSERVABLES.values() if o.present(data)]
    if not names:
        if not available:
            raise ParameterError(f"{data.source}: no observable to fit (DOP, BRDF, Stokes, AoP or Mueller columns)")
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
        self._jitted = None  # (pointwise, total), compiled at the first call

    @property
    def batch_sets(self) -> int:
        """How many parameter sets one vectorised evaluation should take: intermediate arrays of
        sets x geometries x (16 Mueller or 4 Stokes) values stay near 4 million numbers (~32 MB); a power of
        two, the size the compiled likelihood pads to anyway."""
        sets = max(1, 4_000_000 // ((16 if self.needs_mueller else 4) * len(self.data)))
        return 1 << (sets.bit_length() - 1)

    @property
    def n_obs(self) -> int:
        return len(self.observables) * len(self.data)

    def observable_of(self, channel: str):
        return self._owner[channel]

    def observed(self) -> dict[str, np.ndarray]:
        return dict(self._y)

    def predict(self, model_params: dict) -> dict[str, np.ndarray]:
        pred = self.model.evaluate(model_params, self.geometry, mueller=self.needs_mueller, check=False)
        out = {}
        for o in self.objects:
            out.update(o.predict(pred))
        return {ch: out[ch] for ch in self.observables}

    def noise_parameter(self, channel: str) -> str | None:
        """The nuisance parameter holding ``channel``'s noise, or None when the file gives errors."""
        return None if channel in self._errors else self._owner[channel].noise_parameter(channel).name

    def inferred(self, channel: str) -> bool:
        return channel not in self._errors

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
        return self.residual(channel, mu) / scale

    def replicate(self, channel: str, mu, scale, rng: np.random.Generator):
        return self._owner[channel].replicate(channel, mu, scale, self.inferred(channel), rng)

    def pointwise(self, params: dict) -> np.ndarray:
        """Log-likelihood per observation, shape (P, n_obs), for P parameter sets (model and noise parameters)."""
        return self._call(0, params)

    def total(self, params: dict) -> np.ndarray:
        """Log-likelihood per parameter set, (P,): the pointwise sum, fused (nothing of size n_obs is kept)."""
        return self._call(1, params)

    def _call(self, which: int, params: dict) -> np.ndarray:
        if self._jitted is None:
            self._jitted = self._compile()
        values, n_sets = {}, 0
        for name, v in params.items():
            if np.ndim(v) == 0:
                values[name] = float(v)
            else:
                v = np.asarray(v, float).reshape(-1)
                values[name], n_sets = v[:, None], max(n_sets, v.size)
        out = np.asarray(self._jitted[which](padded(values, n_sets), self._inputs))
        return out[:n_sets] if n_sets else out

    def _compile(self):
        program = Program(self.model, self.geometry, self.needs_mueller)
        model_names = {p.name for p in self.model.parameters}
        mueller = self.needs_mueller
        self._inputs = {"model": program.inputs, "y": {ch: jnp.asarray(y) for ch, y in self._y.items()},
                        "errors": {ch: jnp.asarray(e) for ch, e in self._errors.items()},
                        "profiles": {ch: jnp.asarray(f) for ch, f in self._profile.items()}}

        def pointwise(values, inputs):
            total, dop = program({k: v for k, v in values.items() if k in model_names}, inputs["model"])
            prediction = Prediction(stokes=total[:, 0] if mueller else total, dop=dop, mueller=total if mueller else None)
            predicted = {}
            for o in self.objects:
                predicted.update(o.predict(prediction))
            blocks = []
            for ch in self.observables:
                if ch in inputs["errors"]:
                    scale = inputs["errors"][ch]
                else:
                    scale = values[self.noise_parameter(ch)] * inputs["profiles"].get(ch, 1.0)
                resid = self._owner[ch].residual(ch, inputs["y"][ch], predicted[ch], self.inferred(ch))
                blocks.append(jnp.broadcast_to(self._logpdf(ch, resid, scale), jnp.shape(predicted[ch])))
            return jnp.concatenate(blocks, axis=-1)

        return jax.jit(pointwise), jax.jit(lambda values, inputs: pointwise(values, inputs).sum(axis=-1))

    def _logpdf(self, channel, resid, scale):
        if not self.robust:
            return self._owner[channel].log_density(resid, scale)
        xp = array_module(resid, scale)
        nu = self.nu
        const = gammaln((nu + 1) / 2) - gammaln(nu / 2) - 0.5 * math.log(nu * math.pi)
        return const - xp.log(scale) - 0.5 * (nu + 1) * xp.log1p((resid / scale) ** 2 / nu)
