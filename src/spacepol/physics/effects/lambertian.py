"""The ``lambertian`` effect: depolarized Lambertian reflection, rho_l / pi."""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from ...priors import Uniform
from ..effect import Effect
from ..parameter import Parameter


class Lambertian(Effect):
    """The ``lambertian`` effect: depolarized Lambertian reflection, rho_l / pi."""
    name = "lambertian"
    mirror_symmetric = True  # isotropic: M(-dphi) = D M(dphi) D
    hidden_values = ({"rho_l": 0.05}, {"rho_l": 0.3})  # a small and a large value, for the hidden-effect suite
    parameters = (
        Parameter("rho_l", "", Uniform(0.0, 1.0), 0.1, "albedo of the depolarized Lambertian diffuse light", physical=(0.0, 1.0)),
    )
    description = (
        "Depolarized Lambertian diffuse reflection f = (rho_l/pi) diag(1,0,0,0): the same radiance in "
        "every direction, reciprocal, energy-conserving for rho_l <= 1. The physical alternative to the "
        "paper's `body` term, whose cos(theta_r) factor makes it neither Lambertian nor reciprocal; like "
        "it, it lowers DOP wherever the specular lobe is weak."
    )
    slot = "body"
    removable = True
    intensity = "rho_l"
    neutral = {"rho_l": 0.0}

    def lobe(self, ctx):
        return ctx.depolarized((ctx["rho_l"] / np.pi) * jnp.ones_like(ctx.geometry.cos_tr))
