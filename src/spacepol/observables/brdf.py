"""BRDF (sr^-1): Gaussian in BRDF with the file's ``brdf_err``; without it, Gaussian in log BRDF with an
inferred relative noise (BRDF errors are multiplicative: gain, spot size, solid angle)."""

from __future__ import annotations

import numpy as np

from ..errors import InputFileError
from ..priors import LogUniform
from ..physics.arrays import array_module
from ..physics.parameter import Parameter
from .base import ColumnObservable

_FLOOR = 1e-300


class BRDF(ColumnObservable):
    """The BRDF (sr^-1): with the file's errors, Gaussian in the BRDF; inferred, a relative noise (Gaussian in
    log BRDF)."""

    name = "brdf"
    label = "BRDF (sr^-1)"
    title = "BRDF"
    listing_order = 20
    design_noise = 0.05  # 5 %
    relative_noise = True
    noise = Parameter("sigma_brdf_rel", "", LogUniform(1e-3, 2.0), 0.05,
                      "relative BRDF noise, sd of log BRDF (inferred: the file has no brdf_err)", physical=(1e-12, np.inf))

    def predict(self, prediction):
        return {"brdf": prediction.brdf}

    def check_value(self, column, value, path, line):
        super().check_value(column, value, path, line)
        if column == "brdf" and value < 0:
            raise InputFileError(path, f"negative intensity {value:g}", line=line, column=column)

    def noise_space(self, channel, mu, inferred):
        if inferred:
            xp = array_module(mu)
            return xp.log(xp.maximum(mu, _FLOOR))
        return mu

    def reciprocal_differences(self, channel, observed, pairs, inferred):
        """The BRDF is the same with source and detector swapped (Helmholtz)."""
        (b, _), (a, _) = self.reciprocal_members(channel, pairs)
        return self.residual(channel, observed[channel][b], observed[channel][a], inferred)

    def reciprocal_members(self, channel, pairs):
        """(rows b, BRDF) and (rows a, BRDF) of each distinct pair."""
        a, b = pairs[pairs[:, 0] != pairs[:, 1]].T
        return (b, channel), (a, channel)

    def replicate(self, channel, mu, scale, inferred, rng):
        z = rng.standard_normal(np.shape(mu))
        return mu * np.exp(scale * z) if inferred else mu + scale * z
