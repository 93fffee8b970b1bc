"""The ``specular`` effect: microfacet reflection with the exact Fresnel Mueller matrix."""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from ...priors import Uniform
from .. import facets, fresnel
from ..effect import Context, Effect, Ratio
from ..parameter import Parameter


class Specular(Effect):
    """The ``specular`` effect: microfacet reflection with the exact Fresnel Mueller matrix."""
    name = "specular"
    mirror_symmetric = True  # isotropic: M(-dphi) = D M(dphi) D
    essential = True  # every other lobe and modifier is defined relative to it
    parameters = (
        Parameter("n", "", Uniform(0.1, 5.0), 1.5, "real part of the complex refractive index N = n + ik", physical=(1e-6, np.inf)),
        Parameter("k", "", Uniform(0.0, 20.0), 0.0, "extinction coefficient, imaginary part of N", physical=(0.0, np.inf)),
        Parameter("sigma", "", Uniform(0.02, 0.8), 0.2, "facet slope standard deviation per axis (eq 1)", physical=(1e-6, np.inf)),
        Parameter("ks", "", Uniform(0.0, 1.0), 0.5, "specular weight k_s of f = f_dd + k_s f_sp (eq 10)", physical=(0.0, 1.0)),
    )
    description = (
        "Mirror-like reflection from randomly tilted microfacets (paper eqs 1-6, 20-21). Facet "
        "slopes are Gaussian with standard deviation sigma per axis (Beckmann alpha = sqrt(2) sigma); each "
        "facet reflects with the exact Fresnel Mueller matrix of the complex index n + ik at the local "
        "angle beta, rotated from the facet's plane of incidence into the macroscopic planes (eta_i, "
        "eta_r). It polarizes light perpendicular to the plane of scattering (s), most strongly near "
        "Brewster's angle for dielectrics; roughness sigma widens the lobe but leaves the DOP of the "
        "lobe itself unchanged."
    )
    intensity = "ks"
    branches = ({"k": 0.0},)  # dielectrics (PTFE, paints, glass): k < 0.05 is 0.25 % of the default k prior

    def distribution(self, ctx: Context):
        """The facet slope distribution at the half-vector: Beckmann (or GGX, anisotropic when configured)."""
        geo = ctx.geometry
        if ctx.anisotropic_slopes is not None:
            sx, sy, psi = ctx.anisotropic_slopes
            fn = facets.ggx_anisotropic if ctx.facet_shape == "ggx" else facets.beckmann_anisotropic
            return fn(geo.tan2_alpha, geo.sec4_alpha, geo.phi_h, sx, sy, psi)
        fn = facets.ggx if ctx.facet_shape == "ggx" else facets.beckmann
        return fn(geo.tan2_alpha, geo.sec4_alpha, ctx["sigma"])

    def lobe(self, ctx: Context):
        # The specular lobe is assembled by the Model (it must pass through specular_factor
        # and modify_specular hooks before it is added), see specular_lobe().
        return None

    def specular_lobe(self, ctx: Context, factor=None):
        """The lobe times ``factor`` (the product of the shadowing factors, or None)."""
        geo = ctx.geometry
        scalar = ctx["ks"] * self.distribution(ctx) * geo.specular_jacobian
        if factor is not None:
            scalar = scalar * factor
        if ctx.mueller:
            if ctx.fresnel_amplitudes is not None:
                entries = fresnel.matrix_entries(*ctx.fresnel_amplitudes(geo.cos_beta, geo.sin2_beta))
                return fresnel.rotated(entries, geo.mueller_basis, scalar)
            entries = fresnel.interface_matrix_entries(ctx["n"], ctx["k"], geo.cos_beta, geo.sin2_beta, scalar)
            return fresnel.rotated(entries, geo.mueller_basis)
        if ctx.fresnel_amplitudes is not None:
            r_s, r_p = ctx.fresnel_amplitudes(geo.cos_beta, geo.sin2_beta)
            big_rs, big_rp = jnp.abs(r_s) ** 2, jnp.abs(r_p) ** 2
        elif ctx.up_to_scale:  # R_s +- R_p = N_s (D_p +- N_p) / (D_s D_p): the denominator is kept aside
            num_s, den_s, num_p, den_p = fresnel.power_terms(ctx["n"], ctx["k"], geo.cos_beta, geo.sin2_beta, geo.sin_tan_beta)
            s0, s1 = 0.5 * scalar * num_s * (den_p + num_p), 0.5 * scalar * num_s * (den_p - num_p)
            # (S1, S2) = s1 (cos 2 eta, -sin 2 eta): its length is |s1|
            return Ratio(fresnel.stokes_rows(s0, s1, geo.stokes_basis), den_s * den_p, polarized=s1)
        else:
            big_rs, big_rp = fresnel.power(ctx["n"], ctx["k"], geo.cos_beta, geo.sin2_beta, geo.sin_tan_beta)
        s0, s1 = 0.5 * scalar * (big_rs + big_rp), 0.5 * scalar * (big_rs - big_rp)  # in the facet's basis
        return fresnel.combined((s0, s1), geo.stokes_basis, 1)
