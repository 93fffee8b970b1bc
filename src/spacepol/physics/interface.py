"""Depolarized light under a smooth surface: Fresnel power transmission in and out, as Mueller rows."""

from __future__ import annotations

import jax.numpy as jnp

from . import fresnel


def through_interface(ctx, scale, n, k):
    """scale x T(theta_r) D T(theta_i): depolarized light under the surface, Fresnel-transmitted in and out."""
    geo = ctx.geometry
    return ctx.first_column_times_row([scale * c for c in transmission_row(n, k, geo.cos_tr)], transmission_row(n, k, geo.cos_ti))


def transmission_row(n, k, cos_t):
    """First row (= first column) of the Mueller matrix of Fresnel power transmission T = 1 - R into the
    surface at angle theta from the normal (s and p transmittances; reciprocal, so the same out)."""
    sin2 = 1.0 - cos_t**2
    r_s, r_p = fresnel.power(n, k, cos_t, sin2, sin2 / cos_t)
    t_s, t_p = 1.0 - r_s, 1.0 - r_p
    zero = jnp.zeros_like(t_s)
    return [0.5 * (t_s + t_p), 0.5 * (t_s - t_p), zero, zero]
