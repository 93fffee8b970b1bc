"""Fresnel reflection against tmm (an independent transfer-matrix implementation)."""

import numpy as np
import pytest
import tmm

from spacepol.physics import fresnel

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
