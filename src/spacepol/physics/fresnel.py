"""Fresnel reflection at a facet for a complex index N = n + ik (time dependence exp(-i w t)).

Two forms, checked against each other and against ``tmm``:

* ``amplitudes``: complex r_s, r_p (needed for the full Mueller matrix, thin films).
  Convention: the Stokes basis of each beam is (s, p, d) right-handed with the same s for the
  incident and reflected beam, so at normal incidence r_s = -r_p (a mirror).
* ``power``: the real power reflectances R_s, R_p of paper eqs 14-19 with the corrected eq 15
  (``sin(beta) tan(beta)``; ERRATA.md).  Cheaper: it is what DOP and BRDF need for unpolarized
  incidence, so it is the hot path of an inversion.

``power_paper_eq15`` keeps the printed (wrong) eq 15 so a test can show what the typo does.
"""

from __future__ import annotations

import numpy as np


def amplitudes(N, cos_theta, sin2_theta):
    """Complex amplitude reflection coefficients (r_s, r_p) from vacuum onto index ``N``."""
    N = np.asarray(N, dtype=complex)
    root = np.sqrt(N**2 - sin2_theta)  # = N cos(theta_t); principal branch has Im >= 0
    r_s = (cos_theta - root) / (cos_theta + root)
    r_p = (N**2 * cos_theta - root) / (N**2 * cos_theta + root)
    return r_s, r_p


def film_amplitudes(N_substrate, n_film, thickness_um, wavelength_um, cos_theta, sin2_theta):
    """(r_s, r_p) of a substrate under one homogeneous film (Airy summation of the two interfaces)."""
    n_film = np.asarray(n_film, dtype=complex)
    N_substrate = np.asarray(N_substrate, dtype=complex)
    root_f = np.sqrt(n_film**2 - sin2_theta)  # n_f cos(theta_f)
    root_s = np.sqrt(N_substrate**2 - sin2_theta)
    r01_s = (cos_theta - root_f) / (cos_theta + root_f)
    r12_s = (root_f - root_s) / (root_f + root_s)
    r01_p = (n_film**2 * cos_theta - root_f) / (n_film**2 * cos_theta + root_f)
    r12_p = (N_substrate**2 * root_f - n_film**2 * root_s) / (N_substrate**2 * root_f + n_film**2 * root_s)
    phase = np.exp(2j * (2 * np.pi / wavelength_um) * thickness_um * root_f)
    r_s = (r01_s + r12_s * phase) / (1 + r01_s * r12_s * phase)
    r_p = (r01_p + r12_p * phase) / (1 + r01_p * r12_p * phase)
    return r_s, r_p


def _a_b2(n, k, sin2_theta):
    """A and B^2 of eqs 16-19, without cancellation.

    A^2 = (sqrt(C) + D)/2 and B^2 = (sqrt(C) - D)/2 with A^2 B^2 = n^2 k^2: where one of the two
    is a difference of nearly equal numbers it is taken from the product instead (for weak
    absorption, B^2 ~ n^2 k^2 / D would otherwise be lost to rounding).  Same arithmetic as
    the compiled kernel.
    """
    d = n**2 - k**2 - sin2_theta
    nk2 = (n * k) * (n * k)
    sqrt_c = np.sqrt(4 * nk2 + d**2)
    a2 = 0.5 * (sqrt_c + d)
    b2 = 0.5 * (sqrt_c - d)
    with np.errstate(divide="ignore", invalid="ignore"):
        a2, b2 = (np.where(a2 < 1e-3 * b2, nk2 / b2, a2), np.where((b2 < 1e-3 * a2) & ~(a2 < 1e-3 * b2), nk2 / a2, b2))
    return np.sqrt(np.maximum(a2, 0.0)), b2


def power(n, k, cos_theta, sin2_theta, sin_tan_theta):
    """Power reflectances (R_s, R_p), eqs 14-19 with the corrected eq 15.

    ``sin_tan_theta`` is sin(theta) tan(theta), passed in because it is a geometry-only term.
    """
    a, b2 = _a_b2(n, k, sin2_theta)
    r_s = ((a - cos_theta) ** 2 + b2) / ((a + cos_theta) ** 2 + b2)
    r_p = r_s * ((a - sin_tan_theta) ** 2 + b2) / ((a + sin_tan_theta) ** 2 + b2)
    return r_s, r_p


def power_paper_eq15(n, k, cos_theta, sin2_theta):
    """The paper's printed eq 15 (sin*cos instead of sin*tan).  Wrong; kept for a regression test."""
    a, b2 = _a_b2(n, k, sin2_theta)
    r_s = ((a - cos_theta) ** 2 + b2) / ((a + cos_theta) ** 2 + b2)
    sin_cos = np.sqrt(sin2_theta) * cos_theta
    r_p = r_s * ((a - sin_cos) ** 2 + b2) / ((a + sin_cos) ** 2 + b2)
    return r_s, r_p


def rotated_mueller(r_s, r_p, cos_2in, sin_2in, cos_2out, sin_2out, scale=1.0):
    """``scale`` x L(eta_out) M_F L(eta_in): eq 21's non-depolarizing Mueller matrix of reflection
    M_F = [[a, b, 0, 0], [b, a, 0, 0], [0, 0, c, d], [0, 0, -d, c]] (a, b = (|r_s|^2 +- |r_p|^2) / 2,
    c + id = r_s r_p*) between the Stokes-basis rotations
    L(eta) = [[1, 0, 0, 0], [0, c, s, 0], [0, -s, c, 0], [0, 0, 0, 1]] (c, s = cos 2 eta, sin 2 eta).

    Written out element by element: M_F has only eight non-zero entries and L rotates one 2 x 2 block,
    so the product costs ~30 multiplications per point where two general 4 x 4 products cost 128."""
    rs2, rp2 = np.abs(r_s) ** 2, np.abs(r_p) ** 2
    cross = r_s * np.conj(r_p)
    a, b = 0.5 * (rs2 + rp2) * scale, 0.5 * (rs2 - rp2) * scale
    c, d = cross.real * scale, cross.imag * scale
    a, b, c, d, ci, si, co, so = np.broadcast_arrays(a, b, c, d, cos_2in, sin_2in, cos_2out, sin_2out)
    out = np.zeros((4, 4) + a.shape)
    out[0, 0], out[0, 1], out[0, 2] = a, b * ci, b * si
    out[1, 0], out[2, 0] = b * co, -b * so
    aco, cso, aso, cco = a * co, c * so, a * so, c * co
    out[1, 1], out[1, 2] = aco * ci - cso * si, aco * si + cso * ci
    out[2, 1], out[2, 2] = -aso * ci - cco * si, cco * ci - aso * si
    out[1, 3], out[2, 3] = so * d, co * d
    out[3, 1], out[3, 2], out[3, 3] = d * si, -d * ci, c
    return out


# The internal hemispherical reflectance is a cosine-weighted average over internal angles; quadrature on
# SCATMECH's grid (0 to 90 deg in 0.2 deg steps, Diffuse_Subsurface_BRDF_Model), so the two agree to
# rounding. The trapezoid rule on it errs by ~1e-5 of the value (the kink at the critical angle).
_INTERNAL_ANGLES = np.linspace(0.0, 0.5 * np.pi, 451)
_INTERNAL_WEIGHTS = np.sin(2.0 * _INTERNAL_ANGLES)


def internal_reflectance(n, cos_theta):
    """Unpolarized reflectance (R_s + R_p)/2 of light inside a transparent medium of index n meeting its
    surface (to vacuum) at internal angle theta: ``amplitudes`` with the relative index 1/n; 1 beyond the
    critical angle (total internal reflection)."""
    r_s, r_p = amplitudes(1.0 / np.asarray(n, float), cos_theta, 1.0 - cos_theta**2)
    return 0.5 * (np.abs(r_s) ** 2 + np.abs(r_p) ** 2)


def hemispherical_internal_reflectance(n):
    """The share of diffuse light inside a transparent medium of index n that its surface reflects back
    in: the cos(theta) sin(theta) d(theta) weighted average of ``internal_reflectance``. Shape of ``n``."""
    n = np.asarray(n, float)[..., None]
    r = internal_reflectance(n, np.cos(_INTERNAL_ANGLES))
    return np.sum(r * _INTERNAL_WEIGHTS, axis=-1) / np.sum(_INTERNAL_WEIGHTS)
