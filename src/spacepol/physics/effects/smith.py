"""The ``smith`` effect: Smith's uncorrelated shadowing-masking for the specular lobe's facet statistics."""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from .. import facets
from ..effect import Effect


class Smith(Effect):
    """The ``smith`` effect: Smith's uncorrelated shadowing-masking for the specular lobe's facet statistics."""
    name = "smith"
    mirror_symmetric = True  # isotropic: M(-dphi) = D M(dphi) D
    excludes = ("shadowing",)
    requires = ("specular",)
    description = (
        "Smith's uncorrelated shadowing-masking G1(theta_i) G1(theta_r) for the same facet statistics "
        "as the specular lobe (exact Lambda for Gaussian slopes, or Trowbridge-Reitz with ggx; "
        "anisotropic widths projected on each beam's azimuth). Physically consistent replacement of "
        "the paper's empirical `shadowing`; darkens grazing geometries, DOP of the lobe unchanged."
    )
    slot = "shadowing"
    removable = True

    # Exact Lambda; renderers use Walter et al.'s rational fit (facets.smith_g1_beckmann_walter).
    beckmann_g1 = staticmethod(facets.smith_g1_beckmann)

    def specular_factor(self, ctx):
        geo = ctx.geometry
        g1 = facets.smith_g1_ggx if ctx.facet_shape == "ggx" else self.beckmann_g1
        tan_i, tan_r = geo.tan_ti, geo.tan_tr
        if ctx.anisotropic_slopes is not None:
            sx, sy, psi = ctx.anisotropic_slopes
            phi_i = jnp.where(geo.theta_i < 0, np.pi, 0.0)
            phi_r = -jnp.radians(geo.dphi) + jnp.where(geo.theta_r < 0, np.pi, 0.0)
            var_i = facets.slope_widths(sx, sy, psi, phi_i)[1]
            var_r = facets.slope_widths(sx, sy, psi, phi_r)[1]
        else:
            var_i = var_r = ctx["sigma"] ** 2
        return g1(tan_i, var_i) * g1(tan_r, var_r)
