"""Normalised Stokes parameters q = S1/S0 and u = S2/S0 for unpolarized incidence (s-polarized light has
q > 0). They carry the sign and orientation of the polarization that DOP discards (DOP = sqrt(q^2 + u^2)
when S3 = 0), so use them instead of DOP, not with it. One inferred noise level for both."""

from __future__ import annotations

import numpy as np

from ..priors import LogUniform
from ..physics.arrays import array_module
from ..physics.parameter import Parameter
from .base import Observable


def _normalised(stokes, row):
    s0 = array_module(stokes).where(stokes[0] > 0, stokes[0], np.inf)
    return stokes[row] / s0


class Stokes(Observable):
    """The normalised Stokes parameters q = S1/S0 and u = S2/S0 of the scattered light (unpolarized incidence)."""

    name = "stokes"
    scale_free = True
    channels = ("q", "u")
    label = "normalised Stokes"
    contains = ("dop", "aop")
    noise = Parameter("sigma_qu", "", LogUniform(1e-4, 0.5), 0.01,
                      "noise of the normalised Stokes parameters q, u (inferred)", physical=(1e-12, np.inf))

    def present(self, data):
        return data.stokes is not None

    def observed(self, data):
        return {"q": _normalised(data.stokes, 1), "u": _normalised(data.stokes, 2)}

    def predict(self, prediction):
        return {"q": _normalised(prediction.stokes, 1), "u": _normalised(prediction.stokes, 2)}
