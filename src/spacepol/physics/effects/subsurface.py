"""The ``subsurface`` effect: a Lambertian material under a smooth transparent interface (SCATMECH's model)."""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from ...priors import Uniform
from .. import fresnel
from ..effect import Effect
from ..interface import through_interface
from ..parameter import Parameter


class Subsurface(Effect):
    """The ``subsurface`` effect: a Lambertian material under a smooth transparent interface (SCATMECH's model)."""
    name = "subsurface"
    mirror_symmetric = True  # isotropic: M(-dphi) = D M(dphi) D
    hidden_values = ({"rho_s": 0.2}, {"rho_s": 0.7})  # a small and a large value, for the hidden-effect suite
    parameters = (
        Parameter("rho_s", "", Uniform(0.0, 1.0), 0.3, "albedo of the diffusely scattering material under the surface",
                  physical=(0.0, 1.0)),
    )
    requires = ("specular",)
    description = (
        "Light scattered by a diffuse (Lambertian, albedo rho_s) material under a smooth transparent interface "
        "(NIST SCATMECH's Diffuse_Subsurface_BRDF_Model; Germer, Proc. SPIE 5158, 2003): Fresnel transmission "
        "in and out, the radiance divided by n^2 on leaving, and the light the interface reflects back in "
        "(the internal hemispherical reflectance rho_i) recycled, f = rho_s / (pi n^2 (1 - rho_i rho_s)) "
        "T(theta_r) D T(theta_i). The interface is taken as transparent (k = 0) for this light. Reciprocal."
    )
    slot = "body"
    removable = True
    intensity = "rho_s"
    neutral = {"rho_s": 0.0}
    twins = {"polarized_diffuse": "no measurement (for a transparent surface both have the shape T(theta_r) D T(theta_i); "
                                  "rho_pd = rho_s / (n^2 (1 - rho_i rho_s)) converts one albedo into the other)"}

    def lobe(self, ctx):
        n, rho = ctx["n"], ctx["rho_s"]
        recycled = 1.0 / (1.0 - fresnel.hemispherical_internal_reflectance(n) * rho)
        return through_interface(ctx, rho * recycled / (np.pi * n**2), n, jnp.zeros_like(n))
