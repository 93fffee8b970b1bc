"""Fresnel reflection at a facet for a complex index N = n + ik (time dependence exp(-i w t)): power
reflectances, complex amplitudes and the Mueller matrix of reflection, in three forms checked against each other
and against ``tmm``; transmission, and the interface's hemispherical internal reflectance.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np


def amplitudes(N, cos_theta, sin2_theta):
    """Complex amplitude reflection coefficients (r_s, r_p) from vacuum onto index ``N``."""
    N = jnp.asarray(N, dtype=complex)
    root = jnp.sqrt(N**2 - sin2_theta)  # = N cos(theta_t); principal branch has Im >= 0
    r_s = (cos_theta - root) / (cos_theta + root)
    r_p = (N**2 * cos_theta - root) / (N**2 * cos_theta + root)
    return r_s, r_p


def film_amplitudes(N_substrate, n_film, thickness_um, wavelength_um, cos_theta, sin2_theta):
    """(r_s, r_p) of a substrate under one homogeneous film (Airy summation of the two interfaces)."""
    n_film = jnp.asarray(n_film, dtype=complex)
    N_substrate = jnp.asarray(N_substrate, dtype=complex)
    root_f = jnp.sqrt(n_film**2 - sin2_theta)  # n_f cos(theta_f)
    root_s = jnp.sqrt(N_substrate**2 - sin2_theta)
    r01_s = (cos_theta - root_f) / (cos_theta + root_f)
    r12_s = (root_f - root_s) / (root_f + root_s)
    r01_p = (n_film**2 * cos_theta - root_f) / (n_film**2 * cos_theta + root_f)
    r12_p = (N_substrate**2 * root_f - n_film**2 * root_s) / (N_substrate**2 * root_f + n_film**2 * root_s)
    phase = jnp.exp(2j * (2 * np.pi / wavelength_um) * thickness_um * root_f)
    r_s = (r01_s + r12_s * phase) / (1 + r01_s * r12_s * phase)
    r_p = (r01_p + r12_p * phase) / (1 + r01_p * r12_p * phase)
    return r_s, r_p


def _a_b(n, k, sin2_theta):
    """A and B of eqs 16-19 (N cos(theta_t) = A + iB), without cancellation and with finite derivatives.

    A^2 = (sqrt(C) + D)/2 and B^2 = (sqrt(C) - D)/2 with A B = |n k|: the one of the two that is a sum,
    sqrt(big) with big = (sqrt(C) + |D|)/2 (``_larger_half``), is computed as written and the other as |n k| /
    sqrt(big), so weak absorption (B^2 ~ n^2 k^2 / D, which the difference loses to rounding) keeps every digit, and
    no square root is taken of a number that can be 0 (B at k = 0, A under total reflection), whose derivative would
    be infinite (times a zero derivative inside it: NaN in a gradient).
    """
    nk2, big, above = _larger_half(n, k, sin2_theta)
    root = jnp.sqrt(jnp.where(big > 0, big, 1.0))  # big = 0 only where n = k = 0 and sin = 0
    other = jnp.where(big > 0, jnp.abs(n * k) / root, 0.0)
    return jnp.where(above, root, other), jnp.where(above, other, root)


def _larger_half(n, k, sin2_theta):
    """(n^2 k^2, the larger of A^2 and B^2 = (sqrt(C) + |D|)/2, whether it is A^2 (D >= 0))."""
    d = n**2 - k**2 - sin2_theta
    nk2 = (n * k) * (n * k)
    return nk2, 0.5 * (jnp.sqrt(4 * nk2 + d**2) + jnp.abs(d)), d >= 0


def power_terms(n, k, cos_theta, sin2_theta, sin_tan_theta):
    """R_s = N_s / D_s and R_p = R_s N_p / D_p (eqs 14-19, corrected eq 15) as the four sums of squares,
    without a division: (N_s, D_s, N_p, D_p), each > 0 (D) or >= 0 (N).

    Each sum is eqs 16-19's (A -+ x)^2 + B^2 times A^2 + B^2's larger half ``big`` (``_a_b``), which makes
    every term a product: with s = sqrt(big), s A is big (above, D >= 0) or |n k| (below), and big B^2 is
    n^2 k^2 or big^2. The common factor cancels in each ratio, and a caller that needs the reflectances only
    up to a positive factor (DOP: ``compiled``'s up-to-scale programs) divides nowhere. ``big`` = 0 (n = k = 0,
    or k = 0 at n = sin(theta)) leaves the sums unscaled (A = B = 0 there).
    """
    nk2, big, above = _larger_half(n, k, sin2_theta)
    scaled = big > 0
    root = jnp.sqrt(jnp.where(scaled, big, 1.0))
    a_root = jnp.where(scaled, jnp.where(above, big, jnp.abs(n * k)), 0.0)  # sqrt(big) A
    b2_big = jnp.where(scaled, jnp.where(above, nk2, big * big), 0.0)  # big B^2
    num_s = (a_root - cos_theta * root) ** 2 + b2_big
    den_s = (a_root + cos_theta * root) ** 2 + b2_big
    num_p = (a_root - sin_tan_theta * root) ** 2 + b2_big
    den_p = (a_root + sin_tan_theta * root) ** 2 + b2_big
    return num_s, den_s, num_p, den_p


def power(n, k, cos_theta, sin2_theta, sin_tan_theta):
    """Power reflectances (R_s, R_p), eqs 14-19 with the corrected eq 15.

    ``sin_tan_theta`` is sin(theta) tan(theta), passed in because it is a geometry-only term.
    """
    num_s, den_s, num_p, den_p = power_terms(n, k, cos_theta, sin2_theta, sin_tan_theta)
    # two divisions, not one shared one: N_s / D_s is exactly 1 where N_s = D_s (total internal reflection),
    # which keeps the transmittance 1 - R of the diffuse lobes at 0 instead of -1e-16
    r_s = num_s / den_s
    return r_s, r_s * num_p / den_p


def power_paper_eq15(n, k, cos_theta, sin2_theta):
    """The paper's printed eq 15 (sin*cos instead of sin*tan).  Wrong; kept for a regression test."""
    a, b = _a_b(n, k, sin2_theta)
    b2 = b * b
    r_s = ((a - cos_theta) ** 2 + b2) / ((a + cos_theta) ** 2 + b2)
    sin_cos = jnp.sqrt(sin2_theta) * cos_theta
    r_p = r_s * ((a - sin_cos) ** 2 + b2) / ((a + sin_cos) ** 2 + b2)
    return r_s, r_p


def matrix_entries(r_s, r_p):
    """The four distinct entries (a, b, c, d) of eq 21's Fresnel Mueller matrix from complex amplitudes:
    a, b = (|r_s|^2 +- |r_p|^2) / 2 and c + id = r_s r_p*."""
    rs2, rp2 = jnp.abs(r_s) ** 2, jnp.abs(r_p) ** 2
    cross = r_s * jnp.conj(r_p)
    return 0.5 * (rs2 + rp2), 0.5 * (rs2 - rp2), cross.real, cross.imag


def interface_matrix_entries(n, k, cos_theta, sin2_theta, scale=1.0):
    """``matrix_entries`` of a bare interface onto N = n + ik, in real arithmetic, times ``scale``.

    The same numbers as ``matrix_entries(*amplitudes(...))``, about 3x faster compiled: complex square roots
    and divisions are slow on a CPU. N cos(theta_t) = A + iB comes from eqs 16-19 (``_a_b``: Re and Im of the
    principal root), then r_s = (c - A - iB) / (c + A + iB), r_p = (N^2 c - A - iB) / (N^2 c + A + iB), and all
    four entries share one division by |D_s|^2 |D_p|^2.

    ``scale`` (the lobe's k_s D G / (4 cos cos)) goes into that division's numerator: XLA then stores one
    (sets x geometries) array for both, and the Mueller matrix's loop, which reads its stored inputs once for
    each of the 16 elements, reads three instead of four (memory-bound at 64 sets x 100,000 geometries:
    41-46 -> 51-55 M evaluations/s; 4,096 x 84: 81-91 -> 100-106, interleaved in one process)."""
    a, b = _a_b(n, k, sin2_theta)
    eps_re, eps_im = n * n - k * k, 2.0 * n * k  # N^2
    num_s_re, num_s_im = cos_theta - a, -b
    den_s_re, den_s_im = cos_theta + a, b
    num_p_re, num_p_im = eps_re * cos_theta - a, eps_im * cos_theta - b
    den_p_re, den_p_im = eps_re * cos_theta + a, eps_im * cos_theta + b
    den_s2 = den_s_re * den_s_re + den_s_im * den_s_im
    den_p2 = den_p_re * den_p_re + den_p_im * den_p_im
    inverse = scale / (den_s2 * den_p2)
    rs2 = (num_s_re * num_s_re + num_s_im * num_s_im) * den_p2 * inverse
    rp2 = (num_p_re * num_p_re + num_p_im * num_p_im) * den_s2 * inverse
    # r_s r_p* = N_s N_p* D_s* D_p / (|D_s|^2 |D_p|^2)
    x_re, x_im = num_s_re * num_p_re + num_s_im * num_p_im, num_s_im * num_p_re - num_s_re * num_p_im
    y_re, y_im = den_s_re * den_p_re + den_s_im * den_p_im, den_s_re * den_p_im - den_s_im * den_p_re
    return 0.5 * (rs2 + rp2), 0.5 * (rs2 - rp2), (x_re * y_re - x_im * y_im) * inverse, (x_re * y_im + x_im * y_re) * inverse


def rotated(entries, basis, scale=1.0):
    """``scale`` x L(eta_out) M_F L(eta_in), eq 21's non-depolarizing Mueller matrix of reflection, from
    M_F's entries (a, b, c, d) and ``Geometry.mueller_basis`` (4, 4, 4, ...): sum_e scale entry_e basis[e].

    Each entry is broadcast over the 16 elements: XLA computes it once. Stacked element by element, as
    before, each of the 16 elements computed the Fresnel coefficients and the facet distribution again
    (paper+polarized_diffuse: 7 M evaluations/s; see ``Geometry.mueller_basis``)."""
    return combined([entry * scale for entry in entries], basis, 2)


def combined(values, basis, lead: int):
    """sum_e values[e] x basis[e]: each value (sets x geometries, or geometries) broadcast over the ``lead``
    leading axes of its basis part (then the geometry's axes: a Stokes vector's 4, a Mueller matrix's 4 x 4),
    so a compiled program computes it once for all of them."""
    total = 0.0
    for value, part in zip(values, basis):
        value = jnp.asarray(value)
        extra = value.ndim - (np.ndim(part) - lead)  # parameter-set axes the geometry does not have
        if extra > 0:
            shape = np.shape(part)
            part = jnp.reshape(part, shape[:lead] + (1,) * extra + shape[lead:])
        total = total + value.reshape((1,) * lead + value.shape) * part
    return total


def stokes_rows(s0, s1, basis):
    """The four rows (S0, S1, S2, S3) of ``combined((s0, s1), basis, 1)`` for ``Geometry.stokes_basis``, whose
    structure they use: light leaving a facet as (1, 0, 0, 0) stays so, and (0, 1, 0, 0) turns into
    (0, cos 2 eta, -sin 2 eta, 0). For a total that stays inside the program (``effect.Ratio``): there XLA
    fuses the whole DOP into one loop only when no value is broadcast over the Stokes axis (a broadcast
    value is computed in a loop of its own and stored), and the structural zeros cost nothing."""
    return [s0, s1 * basis[1, 1], s1 * basis[1, 2], 0.0]


# The internal hemispherical reflectance is a cosine-weighted average over internal angles. Beyond the critical
# angle theta_c the reflectance is 1 (that share is cos^2 theta_c); below it, it rises to 1 as sqrt(theta_c - theta),
# and a fixed grid of angles (SCATMECH's 0.2 deg steps) turns that rise into a kink in n each time theta_c crosses a
# node: a posterior with cusps no optimizer or Hessian can work on. Gauss-Legendre in t, theta = theta_c (1 - t^2),
# makes the rise smooth in t and the average a smooth function of n (Walton's closed form, checked in the tests).
_T_NODES, _T_WEIGHTS = np.polynomial.legendre.leggauss(64)
_T_NODES, _T_WEIGHTS = 0.5 * (_T_NODES + 1.0), 0.5 * _T_WEIGHTS  # on [0, 1]


def internal_reflectance(n, cos_theta):
    """Unpolarized reflectance (R_s + R_p)/2 of light inside a transparent medium of index n meeting its
    surface (to vacuum) at internal angle theta: ``amplitudes`` with the relative index 1/n; 1 beyond the
    critical angle (total internal reflection)."""
    r_s, r_p = amplitudes(1.0 / jnp.asarray(n, float), cos_theta, 1.0 - cos_theta**2)
    return 0.5 * (jnp.abs(r_s) ** 2 + jnp.abs(r_p) ** 2)


def hemispherical_internal_reflectance(n):
    """The share of diffuse light inside a transparent medium of index n that its surface reflects back
    in: the cos(theta) sin(theta) d(theta) weighted average of ``internal_reflectance``, a smooth function of n.
    Shape of ``n``."""
    n = jnp.asarray(n, float)[..., None]
    # theta_c = 90 deg where n <= 1 (no total internal reflection); kept off arcsin's infinite slope at 1
    theta_c = jnp.arcsin(jnp.minimum(1.0 / n, 1.0 - 1e-12))
    theta = theta_c * (1.0 - _T_NODES**2)
    below = internal_reflectance(n, jnp.cos(theta)) * jnp.sin(2.0 * theta) * 2.0 * theta_c * _T_NODES
    return jnp.sum(below * _T_WEIGHTS, axis=-1) + jnp.cos(theta_c[..., 0]) ** 2
