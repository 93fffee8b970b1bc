"""The paper's empirical shadowing/masking function (eqs 7-8, with the ERRATA correction).

    G = (1 + w_p |tan t_ip tan t_rp| / (1 + sigma_r tan b_p)) / ((1 + w_p tan^2 t_ip)(1 + w_p tan^2 t_rp))
    w_p = sigma_p (1 + u_p sin(alpha) / (sin(alpha) + v_p cos(alpha)))
    tan t_ip = tan(t_i) (sin t_i + sin t_r cos phi_r) / (2 sin(alpha) cos(beta))
    tan t_rp = tan(t_r) (sin t_r + sin t_i cos phi_r) / (2 sin(alpha) cos(beta))
    tan b_p  = |cos t_i - cos t_r| / (2 sin(alpha) cos(beta))            (corrected)

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import jax.numpy as jnp

PAPER_CONSTANTS = {"sigma_p": 0.0136, "sigma_r": 0.0136, "u_p": 9.0, "v_p": 1.0}


def paper_shadowing(geo, sigma_p, sigma_r, u_p, v_p):
    """The paper's shadowing-masking function (eq 12 with its constants sigma_p, sigma_r, u_p, v_p) at the geometry."""
    ti, tr = jnp.radians(geo.theta_i), jnp.radians(geo.theta_r)
    cos_phi_r = jnp.cos(jnp.radians(geo.dphi))
    horizontal = 2.0 * geo.sin_alpha * geo.cos_beta  # |(k_i + k_r)_xy|
    at_peak = horizontal < 1e-9
    safe = jnp.where(at_peak, 1.0, horizontal)
    proj_i = jnp.where(at_peak, 1.0, (jnp.sin(ti) + jnp.sin(tr) * cos_phi_r) / safe)
    proj_r = jnp.where(at_peak, -1.0, (jnp.sin(tr) + jnp.sin(ti) * cos_phi_r) / safe)
    tan_ip = jnp.tan(ti) * proj_i
    tan_rp = jnp.tan(tr) * proj_r
    tan_bp = jnp.where(at_peak, jnp.abs(jnp.tan(ti)), jnp.abs(jnp.cos(ti) - jnp.cos(tr)) / safe)
    w_p = sigma_p * (1.0 + u_p * geo.sin_alpha / (geo.sin_alpha + v_p * geo.cos_alpha))
    numerator = 1.0 + w_p * jnp.abs(tan_ip * tan_rp) / (1.0 + sigma_r * tan_bp)
    return numerator / ((1.0 + w_p * tan_ip**2) * (1.0 + w_p * tan_rp**2))
