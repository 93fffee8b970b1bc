"""The ``body`` effect: the paper's depolarized body term, cos(theta_r) rho_d / pi."""

from __future__ import annotations

import numpy as np

from ...priors import Uniform
from ..effect import Effect
from ..parameter import Parameter


class Body(Effect):
    """The ``body`` effect: the paper's depolarized body term, cos(theta_r) rho_d / pi."""
    name = "body"
    mirror_symmetric = True  # isotropic: M(-dphi) = D M(dphi) D
    parameters = (
        Parameter("rho_d", "", Uniform(0.0, 1.0), 0.1, "Kubelka-Munk body reflectance rho_d (eq 12)", physical=(0.0, 1.0)),
    )
    reciprocal = False
    description = (
        "Depolarized body (volume) scattering of the Kubelka-Munk model, in the paper's form "
        "f_dd = (cos(theta_r)/pi) rho_d diag(1,0,0,0) (eq 11). Unpolarized, so it lowers DOP wherever the "
        "specular lobe is weak. Note: because of its cos(theta_r) factor it is neither Lambertian "
        "(rho_d/pi would be) nor reciprocal; eq 23's DOP follows only with this depolarizing M^d."
    )
    slot = "body"
    removable = True
    intensity = "rho_d"
    neutral = {"rho_d": 0.0}

    def lobe(self, ctx):
        return ctx.depolarized((ctx["rho_d"] / np.pi) * ctx.geometry.cos_tr)
