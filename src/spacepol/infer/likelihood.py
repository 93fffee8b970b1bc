"""Likelihood of measured DOP (and BRDF) given a model.

* DOP: Gaussian (or Student-t, ``robust=True``) with the file's ``dop_err``; without it the
  noise level ``sigma_dop`` is a nuisance parameter inferred with the rest.
* BRDF: with ``brdf_err``, Gaussian in BRDF; without it, Gaussian in log BRDF with an inferred
  relative noise ``sigma_brdf_rel`` (BRDF errors are multiplicative: gain, spot size, solid angle).
* Stokes: the normalised q = S1/S0 and u = S2/S0 (``--observables q,u``; from s0,s1,s2 columns or
  a Mueller file's first column), Gaussian with one inferred noise ``sigma_qu``. They carry the
  sign and orientation of the polarization that DOP discards (DOP = sqrt(q^2 + u^2) for S3 = 0),
  so use them instead of DOP, not with it.

The pointwise log-likelihood (one entry per observation) is kept for PSIS-LOO.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import gammaln

from ..errors import ParameterError
from ..io.measurements import Dataset
from ..physics.model import Model
from ..physics.parameter import Parameter
from .priors import LogUniform

OBSERVABLES = ("dop", "brdf", "q", "u")
DEFAULT_OBSERVABLES = ("dop", "brdf")
_LOG_2PI = math.log(2 * math.pi)
_BRDF_FLOOR = 1e-300


class Likelihood:
    def __init__(self, data: Dataset, model: Model, observables=None, robust: bool = False, nu: float = 4.0):
        self.data, self.model = data, model
        available = [o for o in OBSERVABLES if getattr(data, o) is not None]
        self.observables = list(observables) if observables else [o for o in available if o in DEFAULT_OBSERVABLES]
        repeated = sorted({o for o in self.observables if self.observables.count(o) > 1})
        if repeated:
            raise ParameterError(f"observables {','.join(self.observables)}: {', '.join(repeated)} named twice "
                                 f"(each observable counts once)")
        for name in self.observables:
            if name not in OBSERVABLES:
                raise ParameterError(f"unknown observable '{name}' (use {', '.join(OBSERVABLES)})")
            if getattr(data, name) is None:
                raise ParameterError(f"{data.source}: observable '{name}' is not in the data (it has {', '.join(available) or 'none'})")
        if not self.observables:
            raise ParameterError(f"{data.source}: no DOP or BRDF data to fit")
        self.robust, self.nu = robust, float(nu)
        self.nuisance: list[Parameter] = []
        self._errors = {}
        for name in self.observables:
            err = getattr(data, f"{name}_err")
            if err is None:
                if _NUISANCE[name] not in self.nuisance:
                    self.nuisance.append(_NUISANCE[name])
            else:
                if np.any(err <= 0):
                    raise ParameterError(f"{data.source}: {name}_err must be > 0 to weigh the fit (found {err.min():g})")
                self._errors[name] = err
        self.geometry = data.geometry
        # observation names that say where a point is (Pareto-k warnings quote them)
        self.labels = [f"{name}[{i}] (theta_i {data.theta_i[i]:g}, theta_r {data.theta_r[i]:g}, dphi {data.dphi[i]:g} deg)"
                       for name in self.observables for i in range(len(data))]

    @property
    def n_obs(self) -> int:
        return len(self.observables) * len(self.data)

    def observed(self) -> dict[str, np.ndarray]:
        return {name: getattr(self.data, name) for name in self.observables}

    def predict(self, model_params: dict) -> dict[str, np.ndarray]:
        pred = self.model.evaluate(model_params, self.geometry, check=False)
        out = {}
        for name in self.observables:
            if name == "dop":
                out[name] = pred.dop
            elif name == "brdf":
                out[name] = pred.brdf
            else:
                s0 = np.where(pred.stokes[0] > 0, pred.stokes[0], np.inf)
                out[name] = pred.stokes[1 if name == "q" else 2] / s0
        return out

    def noise_parameter(self, name: str) -> str | None:
        """The nuisance parameter holding ``name``'s noise, or None when the file gives errors."""
        return None if name in self._errors else _NUISANCE[name].name

    def pointwise(self, params: dict) -> np.ndarray:
        """Log-likelihood per observation, shape (P, n_obs), for P parameter sets."""
        model_names = {p.name for p in self.model.parameters}
        pred = self.predict({k: v for k, v in params.items() if k in model_names})
        blocks = []
        for name in self.observables:
            y, mu = getattr(self.data, name), pred[name]
            if name != "brdf":
                scale = self._errors[name] if name in self._errors else np.asarray(params[_NUISANCE[name].name])[:, None]
                resid = y - mu
            elif "brdf" in self._errors:
                scale, resid = self._errors["brdf"], y - mu
            else:
                scale = np.asarray(params["sigma_brdf_rel"])[:, None]
                resid = np.log(np.maximum(y, _BRDF_FLOOR)) - np.log(np.maximum(mu, _BRDF_FLOOR))
            blocks.append(self._logpdf(resid, scale))
        return np.concatenate(blocks, axis=-1)

    def _logpdf(self, resid, scale):
        z2 = (resid / scale) ** 2
        if not self.robust:
            return -0.5 * z2 - np.log(scale) - 0.5 * _LOG_2PI
        nu = self.nu
        const = gammaln((nu + 1) / 2) - gammaln(nu / 2) - 0.5 * math.log(nu * math.pi)
        return const - np.log(scale) - 0.5 * (nu + 1) * np.log1p(z2 / nu)


_SIGMA_QU = Parameter("sigma_qu", "", LogUniform(1e-4, 0.5), 0.01,
                      "noise of the normalised Stokes parameters q, u (inferred)", physical=(1e-12, np.inf))
_NUISANCE = {
    "q": _SIGMA_QU,
    "u": _SIGMA_QU,
    "dop": Parameter("sigma_dop", "", LogUniform(1e-4, 0.5), 0.01,
                     "DOP noise level (inferred: the file has no dop_err)", physical=(1e-12, np.inf)),
    "brdf": Parameter("sigma_brdf_rel", "", LogUniform(1e-3, 2.0), 0.05,
                      "relative BRDF noise, sd of log BRDF (inferred: the file has no brdf_err)", physical=(1e-12, np.inf)),
}
