"""Fresnel reflection against tmm (an independent transfer-matrix implementation)."""

import numpy as np
import pytest
import tmm

from spacepol.physics import fresnel
from spacepol.physics.geometry import mueller_basis

INDICES = [1.24 + 6.6j, 1.405 + 0.2289j, 1.5 + 0j, 1.58 + 15.7j]
ANGLES_DEG = np.linspace(0.0, 89.0, 90)


def _tmm(N, theta):
    out = {}
    for pol in ("s", "p"):
        res = tmm.coh_tmm(pol, [1.0, N], [np.inf, np.inf], theta, 1.0)
        out[pol] = (res["r"], res["R"])
    return out


@pytest.mark.parametrize("N", INDICES)
def test_power_reflectances_match_tmm(N):
    theta = np.radians(ANGLES_DEG)
    r_s, r_p = fresnel.power(N.real, N.imag, np.cos(theta), np.sin(theta) ** 2, np.sin(theta) * np.tan(theta))
    ref = [_tmm(N, t) for t in theta]
    np.testing.assert_allclose(r_s, [x["s"][1] for x in ref], rtol=0, atol=1e-10)
    np.testing.assert_allclose(r_p, [x["p"][1] for x in ref], rtol=0, atol=1e-10)


@pytest.mark.parametrize("N", INDICES)
def test_complex_amplitudes_match_tmm(N):
    theta = np.radians(ANGLES_DEG)
    r_s, r_p = fresnel.amplitudes(N, np.cos(theta), np.sin(theta) ** 2)
    ref = [_tmm(N, t) for t in theta]
    np.testing.assert_allclose(r_s, [x["s"][0] for x in ref], rtol=0, atol=1e-10)
    np.testing.assert_allclose(r_p, [x["p"][0] for x in ref], rtol=0, atol=1e-10)


def test_thin_film_matches_tmm():
    N, n_film, d, wl = 1.24 + 6.6j, 1.65, 0.12, 0.633
    theta = np.radians(ANGLES_DEG)
    r_s, r_p = fresnel.film_amplitudes(N, n_film, d, wl, np.cos(theta), np.sin(theta) ** 2)
    for pol, ours in (("s", r_s), ("p", r_p)):
        ref = [tmm.coh_tmm(pol, [1.0, n_film, N], [np.inf, d, np.inf], t, wl)["r"] for t in theta]
        np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-10)


@pytest.mark.parametrize("N", [1.24 + 6.6j, 1.405 + 0.2289j])
def test_printed_eq15_would_fail(N):
    """The paper's printed eq 15 (sin*cos) disagrees with tmm far beyond the tolerance."""
    theta = np.radians(ANGLES_DEG)
    _, r_p_paper = fresnel.power_paper_eq15(N.real, N.imag, np.cos(theta), np.sin(theta) ** 2)
    ref = np.array([_tmm(N, t)["p"][1] for t in theta])
    assert np.max(np.abs(r_p_paper - ref)) > 1e-2
    # and in DOP of the specular lobe, the size ERRATA.md quotes (0.17 for Al, 0.31 for black paint)
    r_s, r_p = fresnel.power(N.real, N.imag, np.cos(theta), np.sin(theta) ** 2, np.sin(theta) * np.tan(theta))
    dop_ok = (r_s - r_p) / (r_s + r_p)
    dop_bad = (r_s - r_p_paper) / (r_s + r_p_paper)
    worst = {1.24: 0.17, 1.405: 0.31}[N.real]
    assert np.max(np.abs(dop_ok - dop_bad)) > worst - 0.01


def test_rotated_mueller_is_the_product_of_rotations_and_fresnel_matrix():
    """The closed form equals L(eta_out) @ M_F @ L(eta_in) computed as plain 4 x 4 products."""
    rng = np.random.default_rng(3)
    N = rng.uniform(0.2, 4, 50) + 1j * rng.uniform(0, 8, 50)
    cos_b = rng.uniform(0.05, 1, 50)
    r_s, r_p = fresnel.amplitudes(N, cos_b, 1 - cos_b**2)
    eta_i, eta_r = rng.uniform(-np.pi, np.pi, (2, 50))
    scale = rng.uniform(0.1, 3, 50)

    def rotator(eta):
        c, s = np.cos(2 * eta), np.sin(2 * eta)
        return np.array([[1, 0, 0, 0], [0, c, s, 0], [0, -s, c, 0], [0, 0, 0, 1]], dtype=float)

    entries = fresnel.matrix_entries(r_s, r_p)
    got = fresnel.rotated(entries, mueller_basis(np, np.cos(2 * eta_i), np.sin(2 * eta_i), np.cos(2 * eta_r), np.sin(2 * eta_r)), scale)
    cross = r_s * np.conj(r_p)
    a, b = 0.5 * (abs(r_s) ** 2 + abs(r_p) ** 2), 0.5 * (abs(r_s) ** 2 - abs(r_p) ** 2)
    c, d, zero = cross.real, cross.imag, np.zeros(50)
    m_f = np.array([[a, b, zero, zero], [b, a, zero, zero], [zero, zero, c, d], [zero, zero, -d, c]])  # eq 21
    for j in range(50):
        want = rotator(eta_r[j]) @ m_f[:, :, j] @ rotator(eta_i[j]) * scale[j]
        np.testing.assert_allclose(got[:, :, j], want, rtol=0, atol=1e-14)
    # negative control: the rotations swapped give a different matrix
    swapped = fresnel.rotated(entries, mueller_basis(np, np.cos(2 * eta_r), np.sin(2 * eta_r), np.cos(2 * eta_i), np.sin(2 * eta_i)), scale)
    assert np.max(np.abs(swapped - got)) > 1e-2


def test_real_arithmetic_entries_equal_the_complex_ones():
    """The full-Mueller hot path (real arithmetic) gives the entries of the tmm-checked complex amplitudes,
    over metals, weak absorbers, dielectrics, n < 1 with total internal reflection, and grazing angles."""
    rng = np.random.default_rng(11)
    n = np.concatenate([rng.uniform(0.05, 5.0, 400), [1.5, 0.5, 1.0 + 1e-9, 1.405]])
    k = np.concatenate([rng.uniform(0.0, 20.0, 200), 10.0 ** rng.uniform(-8, 0, 200), [0.0, 0.0, 0.0, 0.2289]])
    theta = np.radians(rng.uniform(0.0, 89.99, 404))
    cos_t, sin2_t = np.cos(theta), np.sin(theta) ** 2
    want = fresnel.matrix_entries(*fresnel.amplitudes(n + 1j * k, cos_t, sin2_t))
    got = fresnel.interface_matrix_entries(n, k, cos_t, sin2_t)
    for name, w, g in zip("abcd", want, got):
        np.testing.assert_allclose(g, w, rtol=0, atol=1e-13, err_msg=name)
    # a lobe's scale folded into the shared division (what the Mueller program passes) scales every entry
    scale = 10.0 ** rng.uniform(-3, 3, 404)
    for name, w, g in zip("abcd", want, fresnel.interface_matrix_entries(n, k, cos_t, sin2_t, scale)):
        np.testing.assert_allclose(g / scale, w, rtol=0, atol=1e-13, err_msg=f"scaled {name}")
    # negative control: swapping s and p changes b and d
    swapped = fresnel.matrix_entries(*fresnel.amplitudes(n + 1j * k, cos_t, sin2_t)[::-1])
    assert np.max(np.abs(np.asarray(swapped[1]) - np.asarray(got[1]))) > 0.1


def test_division_free_terms_give_the_complex_amplitudes_reflectances():
    """``power_terms`` (sums of squares scaled so that nothing is divided; the DOP program never divides them)
    gives |r_s|^2 and |r_p|^2 of the tmm-checked complex amplitudes as N_s / D_s and R_s N_p / D_p, over
    metals, weak absorbers, dielectrics, n < 1 with total internal reflection, and grazing angles; the
    denominators are positive, and beyond the critical angle R_s is exactly 1 (the diffuse lobes' 1 - R is 0)."""
    rng = np.random.default_rng(12)
    n = np.concatenate([rng.uniform(0.05, 5.0, 400), [1.5, 0.5, 1.0 + 1e-9, 1.405]])
    k = np.concatenate([rng.uniform(0.0, 20.0, 200), 10.0 ** rng.uniform(-8, 0, 200), [0.0, 0.0, 0.0, 0.2289]])
    theta = np.radians(rng.uniform(0.0, 89.99, 404))
    cos_t, sin2_t = np.cos(theta), np.sin(theta) ** 2
    r_s, r_p = fresnel.amplitudes(n + 1j * k, cos_t, sin2_t)
    num_s, den_s, num_p, den_p = (np.asarray(t) for t in fresnel.power_terms(n, k, cos_t, sin2_t, np.sin(theta) * np.tan(theta)))
    assert np.all(den_s > 0) and np.all(den_p > 0)
    np.testing.assert_allclose(num_s / den_s, np.abs(r_s) ** 2, rtol=0, atol=1e-13)
    np.testing.assert_allclose(num_s / den_s * num_p / den_p, np.abs(r_p) ** 2, rtol=0, atol=1e-13)
    # the ratio R_s + R_p over R_s - R_p, which is all the DOP needs, without the denominators
    np.testing.assert_allclose(num_s * (den_p - num_p) / (den_s * den_p), np.abs(r_s) ** 2 - np.abs(r_p) ** 2, rtol=0, atol=1e-13)
    n_low = rng.uniform(0.2, 0.95, 50)  # total internal reflection: every angle beyond the critical one
    beyond = np.arcsin(n_low) + rng.uniform(1e-6, 1.0, 50) * (np.radians(89.99) - np.arcsin(n_low))
    r_tir = np.asarray(fresnel.power(n_low, 0.0, np.cos(beyond), np.sin(beyond) ** 2, np.sin(beyond) * np.tan(beyond)))
    assert np.all(r_tir[0] == 1.0) and np.all(r_tir[1] == 1.0)
    # at the critical angle itself (A = B = 0) the sums are left unscaled: R_s = 1, not 0 / 0
    s = 0.6
    critical = fresnel.power(0.6, 0.0, np.sqrt(1 - s**2), s**2, s**2 / np.sqrt(1 - s**2))
    assert np.isclose(float(critical[0]), 1.0, rtol=0, atol=1e-15) and np.isfinite(float(critical[1]))
