"""Angle of polarization (deg, from the s direction towards p, in (-90, 90]) for unpolarized incidence.

Residuals are taken modulo 180 deg (an AoP of 89 deg and one of -89 deg differ by 2 deg). A polarimeter's
noise sigma on q and u scatters the AoP by sigma / (2 DOP) rad: the scatter grows as 1 / DOP and the AoP is
undefined where DOP reaches the noise. So an inferred AoP noise level is the scatter at DOP = 1, scaled by
1 / DOP per row (the measured DOP, or that of the measured Stokes vector; at least 0.05, below which AoP
says nothing); without a measured DOP the level is constant. Per-row ``aop_err`` replaces all this."""

from __future__ import annotations

import numpy as np

from ..priors import LogUniform
from ..physics.arrays import array_module
from ..physics.parameter import Parameter
from .base import ColumnObservable


def wrap_deg(angle):
    """An angle difference brought into [-90, 90) deg (AoP is defined modulo 180 deg)."""
    xp = array_module(angle)
    return (xp.asarray(angle) + 90.0) % 180.0 - 90.0


class AoP(ColumnObservable):
    """The angle of linear polarization (deg, modulo 180); its inferred noise grows as 1 / DOP."""

    name = "aop"
    scale_free = True
    label = "AoP (deg)"
    title = "AoP"
    listing_order = 30
    noise = Parameter("sigma_aop_deg", "deg", LogUniform(1e-2, 30.0), 1.0,
                      "AoP noise at DOP = 1, growing as 1 / DOP (inferred: the file has no aop_err)", physical=(1e-12, np.inf))
    min_dop = 0.05

    def noise_profile(self, channel, data):
        dop = data.get("dop")
        if dop is None and data.get("stokes") is not None:
            s = data.get("stokes")
            dop = np.sqrt(s[1] ** 2 + s[2] ** 2 + s[3] ** 2) / np.where(s[0] > 0, s[0], np.inf)
        return None if dop is None else 1.0 / np.maximum(dop, self.min_dop)

    def predict(self, prediction):
        return {"aop": prediction.aop_deg}

    def residual(self, channel, y, mu, inferred):
        return wrap_deg(y - mu)

    def replicate(self, channel, mu, scale, inferred, rng):
        return wrap_deg(mu + scale * rng.standard_normal(np.shape(mu)))
