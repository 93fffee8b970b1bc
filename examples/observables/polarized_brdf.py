"""A user's observable in one file: the polarized BRDF, P = sqrt(S1^2 + S2^2 + S3^2) for unpolarized incidence of unit
irradiance (sr^-1), i.e. DOP x BRDF: what an imaging polarimeter calibrated in radiance gives without its S0.

    invert-mcmc run data.csv --observables brdf,examples/observables/polarized_brdf.py:PolarizedBRDF --out runs/p
    spacepol.invert("data.csv", "specular+smith", observables="examples/observables/polarized_brdf.py:PolarizedBRDF")

The file's column is ``pbrdf`` (with ``pbrdf_err``, else a relative noise is inferred, Gaussian in log P as BRDF's).
Everything else (the file reader, the likelihood, residuals, figures, the report, the InferenceData) takes it from
the class: its channels, columns, checks, prediction and noise model.
"""

import numpy as np

from spacepol.errors import InputFileError
from spacepol.observables.base import ColumnObservable
from spacepol.physics.arrays import array_module
from spacepol.physics.parameter import Parameter
from spacepol.priors import LogUniform


class PolarizedBRDF(ColumnObservable):
    """The polarized part of the BRDF, sqrt(S1^2 + S2^2 + S3^2) (sr^-1), with a relative (log-normal) noise."""

    name = "pbrdf"
    label = "polarized BRDF (sr^-1)"
    title = "the polarized BRDF"
    relative_noise = True
    design_noise = 0.05
    noise = Parameter("sigma_pbrdf_rel", "", LogUniform(1e-3, 2.0), 0.05,
                      "relative noise of the polarized BRDF, sd of its log (inferred: the file has no pbrdf_err)",
                      physical=(1e-12, np.inf))

    def check_value(self, column, value, path, line):
        super().check_value(column, value, path, line)
        if column == "pbrdf" and value < 0:
            raise InputFileError(path, f"negative polarized BRDF {value:g}", line=line, column=column)

    def predict(self, prediction):
        s = prediction.stokes
        xp = array_module(s)
        squared = s[1] ** 2 + s[2] ** 2 + s[3] ** 2
        # sqrt kept off 0 (its derivative is infinite there)
        return {"pbrdf": xp.where(squared > 0, xp.sqrt(xp.where(squared > 0, squared, 1.0)), 0.0)}

    def noise_space(self, channel, mu, inferred):
        if not inferred:
            return mu
        xp = array_module(mu)
        return xp.log(xp.maximum(mu, 1e-300))

    def replicate(self, channel, mu, scale, inferred, rng):
        z = rng.standard_normal(np.shape(mu))
        return mu * np.exp(scale * z) if inferred else mu + scale * z
