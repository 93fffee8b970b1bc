"""Facet slope statistics: distributions D(alpha) and Smith shadowing for them.

All distributions are normalised so that  integral D cos(alpha) d(omega) = 1  (eq 1).  The
paper's sigma is the standard deviation of each slope component, so Beckmann's alpha (and
Mitsuba's, and SCATMECH's Gaussian slope s) is sqrt(2) * sigma.  ``ggx`` reuses sigma with the
same mapping, a = sqrt(2) sigma, so both have the same curvature at the specular peak.

Written with ``jax.numpy`` (the forward model is compiled by JAX); numpy inputs work too.
"""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np
from jax.scipy import special


def slope_widths(sigma_x, sigma_y, psi_deg, phi):
    """sigma^2 seen along azimuth ``phi`` for anisotropic slopes oriented at ``psi``.

    Returns 1 / (cos^2/sx^2 + sin^2/sy^2), the effective variance of the distribution's
    exponent along phi (used by D), and sx^2 cos^2 + sy^2 sin^2, the projected slope
    variance (used by Smith's G1).
    """
    rel = phi - jnp.radians(psi_deg)
    c2, s2 = jnp.cos(rel) ** 2, jnp.sin(rel) ** 2
    inv_var = c2 / sigma_x**2 + s2 / sigma_y**2
    proj_var = sigma_x**2 * c2 + sigma_y**2 * s2
    return 1.0 / inv_var, proj_var


def beckmann(tan2_alpha, sec4_alpha, sigma):
    """Eq 1: Gaussian slopes with standard deviation sigma per component."""
    var = sigma**2  # per parameter set: divide there, multiply per geometry
    return jnp.exp(tan2_alpha * (-0.5 / var)) * sec4_alpha * (1.0 / (2 * np.pi * var))


def beckmann_anisotropic(tan2_alpha, sec4_alpha, phi_h, sigma_x, sigma_y, psi_deg):
    """Beckmann slope distribution with RMS slopes ``sigma_x``, ``sigma_y`` along axes turned by ``psi_deg``, at
    half-vector tilt (tan^2, sec^4) and azimuth ``phi_h``."""
    var_phi, _ = slope_widths(sigma_x, sigma_y, psi_deg, phi_h)
    return jnp.exp(-tan2_alpha / (2 * var_phi)) * sec4_alpha / (2 * np.pi * sigma_x * sigma_y)


def ggx(tan2_alpha, sec4_alpha, sigma):
    """Trowbridge-Reitz with a = sqrt(2) sigma."""
    a2 = 2 * sigma**2
    return (a2 / np.pi) * sec4_alpha / (a2 + tan2_alpha) ** 2


def ggx_anisotropic(tan2_alpha, sec4_alpha, phi_h, sigma_x, sigma_y, psi_deg):
    """GGX (Trowbridge-Reitz) slope distribution with the same RMS slopes and axes as ``beckmann_anisotropic`` (alpha =
    sqrt(2) sigma)."""
    var_phi, _ = slope_widths(sigma_x, sigma_y, psi_deg, phi_h)
    ax, ay = jnp.sqrt(2) * sigma_x, jnp.sqrt(2) * sigma_y
    return sec4_alpha / (np.pi * ax * ay * (1 + tan2_alpha / (2 * var_phi)) ** 2)


def smith_g1_beckmann(tan_theta, slope_var):
    """Exact Smith masking for Gaussian slopes of variance ``slope_var`` along the view azimuth.

    G1 = 1 / (1 + Lambda),  Lambda = (erf(mu) - 1) / 2 + exp(-mu^2) / (2 mu sqrt(pi)),
    mu = 1 / (sqrt(2 slope_var) tan(theta)).
    """
    tan_theta = jnp.abs(tan_theta)
    # mu = inf at normal incidence (G1 = 1 there) is kept out of the arithmetic, so no branch makes NaN
    flat = tan_theta == 0
    mu = 1.0 / (jnp.sqrt(2 * slope_var) * jnp.where(flat, 1.0, tan_theta))
    lam = 0.5 * (special.erf(mu) - 1.0) + jnp.exp(-(mu**2)) / (2 * mu * np.sqrt(np.pi))
    g1 = 1.0 / (1.0 + lam)
    return jnp.where(flat, 1.0, jnp.where(jnp.isfinite(g1), g1, 0.0))


def smith_g1_beckmann_walter(tan_theta, slope_var):
    """Walter et al. (2007) rational approximation of the Beckmann G1 (< 0.35 % error).

    Renderers (Mitsuba 3 among them) use this form; kept so a test can compare like with like.
    """
    tan_theta = jnp.abs(tan_theta)
    a = 1.0 / (jnp.sqrt(2 * slope_var) * jnp.where(tan_theta == 0, 1e-300, tan_theta))
    g1 = (3.535 * a + 2.181 * a**2) / (1 + 2.276 * a + 2.577 * a**2)
    return jnp.where(a >= 1.6, 1.0, g1)


def smith_g1_ggx(tan_theta, slope_var):
    """Exact Smith masking for Trowbridge-Reitz with a^2 = 2 * slope_var."""
    return 2.0 / (1.0 + jnp.sqrt(1.0 + 2 * slope_var * tan_theta**2))
