"""The built-in effects (DESIGN.md's table, fixed names). Their hooks are JAX code (see ``effect``)."""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from ..priors import Uniform
from . import facets, fresnel
from .effect import Context, Effect, Ratio
from .parameter import Parameter
from .shadowing import PAPER_CONSTANTS, paper_shadowing
from .phase_matrix import PhaseMatrix
from .polarization_memory import PolarizationMemory
from .volume import Volume, VolumeRayleigh


class Specular(Effect):
    """The ``specular`` effect: microfacet reflection with the exact Fresnel Mueller matrix."""
    name = "specular"
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


class Shadowing(Effect):
    """The ``shadowing`` effect: the paper's empirical shadowing/masking of the specular lobe."""
    name = "shadowing"
    parameters = tuple(
        Parameter(name, "", Uniform(lo, hi), PAPER_CONSTANTS[name], text, fixed=True, physical=(0.0, np.inf))
        for name, lo, hi, text in [
            ("sigma_p", 0.0, 0.2, "empirical shadowing strength (eq 8)"),
            ("sigma_r", 0.0, 0.2, "empirical masking relief term (eq 7)"),
            ("u_p", 0.0, 30.0, "growth of w_p with facet tilt (eq 8)"),
            ("v_p", 0.05, 10.0, "tilt scale of w_p (eq 8)"),
        ]
    )
    requires = ("specular",)
    description = (
        "The paper's empirical shadowing/masking G (eqs 7-8, corrected tan(beta_p)): facets hidden "
        "from the source or the detector do not contribute. Darkens the specular lobe at grazing "
        "incidence or exit; it multiplies S0, S1 and S2 alike, so it changes DOP only through the "
        "balance with the diffuse lobes. Its four constants are fixed at the paper's values unless freed."
    )
    slot = "shadowing"
    removable = True

    def specular_factor(self, ctx):
        return paper_shadowing(ctx.geometry, *(ctx[name] for name in PAPER_CONSTANTS))


class Smith(Effect):
    """The ``smith`` effect: Smith's uncorrelated shadowing-masking for the specular lobe's facet statistics."""
    name = "smith"
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


class Body(Effect):
    """The ``body`` effect: the paper's depolarized body term, cos(theta_r) rho_d / pi."""
    name = "body"
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


class PolarizedDiffuse(Effect):
    """The ``polarized_diffuse`` effect: refracted in, depolarized, refracted out (Fresnel transmission twice)."""
    name = "polarized_diffuse"
    parameters = (
        Parameter("rho_pd", "", Uniform(0.0, 1.0), 0.1, "albedo of the subsurface Lambertian light", physical=(0.0, 1.0)),
    )
    requires = ("specular",)
    description = (
        "Light refracted into the material, scattered until depolarized, and refracted out again "
        "(Atkinson & Hancock 2006; the diffuse part of Baek et al. 2018): f = (rho_pd/pi) T(theta_r) D T(theta_i) "
        "with Fresnel power transmittances T = 1 - R of the macroscopic surface. Exit transmission "
        "favours p, so this light is partly polarized parallel to the exit plane (S1 < 0), most at "
        "grazing exit: it raises |DOP| at large theta_r and can flip the sign of S1 far from the specular lobe."
    )
    slot = "body"
    removable = True
    intensity = "rho_pd"
    neutral = {"rho_pd": 0.0}
    twins = {"subsurface": "no measurement on a transparent surface (the same shape T(theta_r) D T(theta_i)); "
                           "on an absorbing one the Fresnel transmission differs slightly"}

    def lobe(self, ctx):
        return _through_interface(ctx, ctx["rho_pd"] / np.pi, ctx["n"], ctx["k"])


def _through_interface(ctx, scale, n, k):
    """scale x T(theta_r) D T(theta_i): depolarized light under the surface, Fresnel-transmitted in and out."""
    geo = ctx.geometry
    return ctx.first_column_times_row([scale * c for c in _transmission(n, k, geo.cos_tr)], _transmission(n, k, geo.cos_ti))


def _transmission(n, k, cos_t):
    """First row (= first column) of the Mueller matrix of Fresnel power transmission T = 1 - R into the
    surface at angle theta from the normal (s and p transmittances; reciprocal, so the same out)."""
    sin2 = 1.0 - cos_t**2
    r_s, r_p = fresnel.power(n, k, cos_t, sin2, sin2 / cos_t)
    t_s, t_p = 1.0 - r_s, 1.0 - r_p
    zero = jnp.zeros_like(t_s)
    return [0.5 * (t_s + t_p), 0.5 * (t_s - t_p), zero, zero]


class Subsurface(Effect):
    """The ``subsurface`` effect: a Lambertian material under a smooth transparent interface (SCATMECH's model)."""
    name = "subsurface"
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
        return _through_interface(ctx, rho * recycled / (np.pi * n**2), n, jnp.zeros_like(n))


class Depolarization(Effect):
    """The ``depolarization`` effect: a fraction of the specular lobe depolarized, its intensity kept."""
    name = "depolarization"
    parameters = (
        Parameter("d_spec", "", Uniform(0.0, 1.0), 0.1, "fraction of the specular lobe depolarized", physical=(0.0, 1.0)),
    )
    requires = ("specular",)
    description = (
        "A fraction d_spec of the specularly reflected light is depolarized by multiple scattering "
        "between facets: the lobe's S1, S2, S3 are scaled by 1 - d_spec, its intensity kept. Lowers the "
        "DOP of the specular lobe at every angle by the same factor."
    )
    twins = {"extinction": "the full Mueller matrix (an analyser acts on the detector side only, depolarization on the light itself: M12 and M21 differ)"}
    separated_by = {"extinction": ("mueller",)}
    neutral = {"d_spec": 0.0}

    def modify_specular(self, ctx, lobe):
        d = ctx["d_spec"]
        if ctx.mueller:
            # (1 - d) M + d M00 diag(1,0,0,0): the depolarized share keeps its intensity for any input.
            return (lobe * (1.0 - d)).at[0, 0].add(d * lobe[0, 0])
        return lobe.at[1:].multiply(1.0 - d)


class Anisotropy(Effect):
    """The ``anisotropy`` effect: slope widths along two turned axes in place of sigma."""
    name = "anisotropy"
    parameters = (
        Parameter("sigma_x", "", Uniform(0.02, 0.8), 0.2, "slope standard deviation along the surface x' axis", physical=(1e-6, np.inf)),
        Parameter("sigma_y", "", Uniform(0.02, 0.8), 0.2, "slope standard deviation along the surface y' axis", physical=(1e-6, np.inf)),
        Parameter("psi", "deg", Uniform(0.0, 180.0), 0.0, "angle of x' from the source azimuth"),
    )
    requires = ("specular",)
    removes = ("sigma",)
    description = (
        "Anisotropic roughness (brushed or rolled metal): slope widths sigma_x, sigma_y along axes "
        "turned by psi from the plane of incidence replace sigma. The specular lobe stretches along "
        "the rough axis, so out-of-plane data change with the sample's rotation."
    )
    splits = {"sigma_x": "sigma", "sigma_y": "sigma"}

    def identifiable(self, values):
        """(sigma_x, sigma_y, psi) and (sigma_y, sigma_x, psi + 90), and psi and psi + 180, describe the same
        surface: order the widths (sigma_x <= sigma_y) and take psi modulo 180 after the swap."""
        sx, sy, psi = (np.asarray(values[n], float) for n in ("sigma_x", "sigma_y", "psi"))
        swap = sx > sy
        return {**values, "sigma_x": np.where(swap, sy, sx), "sigma_y": np.where(swap, sx, sy),
                "psi": np.where(swap, psi + 90.0, psi) % 180.0}

    def configure(self, ctx):
        ctx.anisotropic_slopes = (ctx["sigma_x"], ctx["sigma_y"], ctx["psi"])


class GGX(Effect):
    """The ``ggx`` effect: Trowbridge-Reitz facet slopes in place of Gaussian ones."""
    name = "ggx"
    requires = ("specular",)
    description = (
        "Trowbridge-Reitz (GGX) facet slopes instead of Gaussian ones, width a = sqrt(2) sigma: same "
        "peak curvature, much longer tails, so more light far from the specular direction (and a "
        "smoother fall of DOP away from it)."
    )
    slot = "facets"

    def configure(self, ctx):
        ctx.facet_shape = "ggx"


class OxideLayer(Effect):
    """The ``oxide_layer`` effect: a thin transparent film on the facets (Airy reflection coefficients)."""
    name = "oxide_layer"
    parameters = (
        Parameter("thickness_um", "um", Uniform(0.0, 1.0), 0.05, "film thickness", physical=(0.0, np.inf)),
        Parameter("n_film", "", Uniform(1.0, 2.5), 1.65, "film refractive index (transparent)", physical=(1e-6, np.inf)),
    )
    requires = ("specular",)
    description = (
        "A thin transparent film (native oxide, coating) on the facets: reflection is the coherent sum "
        "of the film's two interfaces (Airy formula), so r_s and r_p, and hence DOP, oscillate with "
        "thickness/wavelength and angle. Needs the wavelength (metadata `wavelength_um` or a column)."
    )
    neutral = {"thickness_um": 0.0}

    def applicable(self, data):
        wavelength = data.wavelength_um
        if wavelength is None or np.any(~np.isfinite(wavelength)):
            return "needs the wavelength (a '# wavelength_um: ...' line or a wavelength_um column)"
        return None

    def configure(self, ctx):
        wavelength = ctx.geometry.wavelength_um
        if wavelength is None:  # (a NaN wavelength is caught by ``applicable`` before any fit)
            from ..errors import ParameterError

            raise ParameterError("oxide_layer needs the wavelength: add '# wavelength_um: ...' to the data file")
        substrate = ctx["n"] + 1j * ctx["k"]
        d, n_f = ctx["thickness_um"], ctx["n_film"]
        ctx.fresnel_amplitudes = lambda cos, sin2: fresnel.film_amplitudes(substrate, n_f, d, wavelength, cos, sin2)


class AngleOffset(Effect):
    """The ``angle_offset`` effect: a goniometer zero error added to both polar angles."""
    name = "angle_offset"
    parameters = (
        Parameter("delta_deg", "deg", Uniform(-3.0, 3.0), 0.0, "goniometer zero error added to theta_i and theta_r", physical=(-89.0, 89.0)),
    )
    description = (
        "A goniometer zero error: the true angles are theta_i + delta and theta_r + delta. Shifts the "
        "whole DOP curve along the angle axis (the geometry is then recomputed for each parameter set)."
    )
    neutral = {"delta_deg": 0.0}

    def transform_geometry(self, params, geometry):
        return geometry.with_offset(params["delta_deg"])


class Extinction(Effect):
    """The ``extinction`` effect: an analyser with a finite extinction ratio (S1, S2, S3 scaled)."""
    name = "extinction"
    parameters = (
        Parameter("e", "", Uniform(0.5, 1.0), 0.95, "analyser efficiency: measured DOP = e x true DOP", physical=(0.0, 1.0)),
    )
    description = (
        "An imperfect analyser (finite extinction ratio) sees S1, S2, S3 scaled by e, so the measured "
        "DOP is e times the true one at every angle; intensity unchanged. On DOP and BRDF data it is a "
        "twin of `depolarization` wherever the diffuse light is unpolarized. An instrument effect on the "
        "detector side, so the measured Mueller matrix is not reciprocal."
    )
    reciprocal = False
    twins = {"depolarization": "the full Mueller matrix (an analyser acts on the detector side only, depolarization on the light itself: M12 and M21 differ)"}
    separated_by = {"depolarization": ("mueller",)}
    neutral = {"e": 1.0}

    def modify_stokes(self, ctx, total):
        return total.at[1:].multiply(ctx["e"])


class DopBias(Effect):
    """The ``dop_bias`` effect: the Rician bias of a DOP estimated from noisy Stokes parameters."""
    name = "dop_bias"
    parameters = (
        Parameter("bias", "", Uniform(0.0, 0.2), 0.02, "noise floor of the DOP estimator", physical=(0.0, 1.0)),
    )
    description = (
        "Noise bias of a measured DOP: with noisy Stokes parameters the DOP estimate is Rician, "
        "sqrt(DOP^2 + bias^2) on average, so low DOP reads high and DOP never reaches 0. Applied to the "
        "measured DOP only (the Stokes vector is the physical one); the estimate may exceed 1 by at most "
        "sqrt(1 + bias^2) - 1."
    )
    neutral = {"bias": 0.0}

    def modify_dop(self, ctx, dop):
        return jnp.sqrt(dop**2 + ctx["bias"] ** 2)


class Lambertian(Effect):
    """The ``lambertian`` effect: depolarized Lambertian reflection, rho_l / pi."""
    name = "lambertian"
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


BUILTIN_EFFECTS = (
    Specular, Shadowing, Smith, Body, PolarizedDiffuse, Depolarization,
    Anisotropy, GGX, OxideLayer, AngleOffset, Extinction, DopBias, Lambertian, Subsurface, Volume, VolumeRayleigh,
    PhaseMatrix, PolarizationMemory,
)
PRESETS = {"paper": "specular+shadowing+body", "torrance-sparrow": "specular+shadowing"}
