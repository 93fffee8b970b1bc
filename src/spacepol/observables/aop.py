"""Angle of polarization (deg, from the s direction towards p, in (-90, 90]) for unpolarized incidence.

Residuals are taken modulo 180 deg (an AoP of 89 deg and one of -89 deg differ by 2 deg). A constant
noise level suits data where the DOP is well above the polarimeter's noise; where the DOP approaches 0
the AoP is undefined and its scatter grows as 1 / DOP: give per-row ``aop_err`` then."""

from __future__ import annotations

import numpy as np

from ..infer.priors import LogUniform
from ..physics.parameter import Parameter
from .base import ColumnObservable


def wrap_deg(angle):
    """An angle difference brought into [-90, 90) deg (AoP is defined modulo 180 deg)."""
    return (np.asarray(angle) + 90.0) % 180.0 - 90.0


class AoP(ColumnObservable):
    name = "aop"
    channels = ("aop",)
    label = "AoP (deg)"
    noise = Parameter("sigma_aop_deg", "deg", LogUniform(1e-2, 30.0), 1.0,
                      "AoP noise level (inferred: the file has no aop_err)", physical=(1e-12, np.inf))

    def predict(self, prediction):
        return {"aop": prediction.aop_deg}

    def residual(self, channel, y, mu, inferred):
        return wrap_deg(y - mu)

    def replicate(self, channel, mu, scale, inferred, rng):
        return wrap_deg(mu + scale * rng.standard_normal(np.shape(mu)))
