"""`volume` and `volume_rayleigh` (first-order volume scattering under the interface) against NIST SCATMECH's
First_Diffuse_BRDF_Model, an independent implementation (Germer), on 600 geometries in and out of the plane of
incidence, all 16 Mueller elements; reciprocity; and the negative controls that show the comparison can fail."""

import numpy as np
import pytest

from spacepol.criticism.reciprocity import reciprocal_image, swapped
from spacepol.physics import Geometry, Model

pytest.importorskip("pySCATMECH")

WAVELENGTH = 0.633


def _corpus(size=600, seed=24):
    """(theta_i, theta_r, phi_s) in degrees, SCATMECH's phi_s = 0 the specular direction: random directions over
    the hemisphere (out of plane), the plane of incidence on both sides, and normal incidence and exit."""
    rng = np.random.default_rng(seed)
    ti = rng.uniform(0.0, 85.0, size)
    tr = rng.uniform(0.0, 85.0, size)
    ps = rng.uniform(-180.0, 180.0, size)
    ps[: size // 6] = 0.0  # in the plane, forward
    ps[size // 6: size // 3] = 180.0  # in the plane, backward (not exactly retro: theta_i != theta_r)
    ti[:5], tr[5:10] = 0.0, 0.0
    return ti, tr, ps


def _scatmech(n, k, phase):
    from pySCATMECH.brdf import BRDF_Model

    return BRDF_Model("First_Diffuse_BRDF_Model", {"lambda": WAVELENGTH, "substrate": f"({n},{k})", "type": 0, **phase})


def _theirs(peer, ti, tr, ps):
    return np.stack([np.array(peer.MuellerBRDF(*np.radians([a, b, c]))) for a, b, c in zip(ti, tr, ps)], axis=-1)


def _albedo(log_absorption, k):
    """SCATMECH's single-scattering albedo: scattering coefficient exp(0) = 1 / um over the attenuation (the phase
    function's absorption exp(log_absorption) plus the host's 4 pi k / lambda)."""
    return 1.0 / (1.0 + np.exp(log_absorption) + 4 * np.pi * k / WAVELENGTH)


def _assert_close(ours, theirs, what):
    """M11 to 1e-6 relative, the normalised elements m_ij = M_ij / M11 to 1e-6 absolute, at every geometry."""
    m11 = theirs[0, 0]
    assert np.all(m11 > 0)
    np.testing.assert_allclose(ours[0, 0], m11, rtol=1e-6, atol=0, err_msg=f"{what}: M11")
    np.testing.assert_allclose(ours / ours[0, 0], theirs / m11, rtol=0, atol=1e-6, err_msg=f"{what}: m_ij")


CODE_WHITNEY = [  # (n, k, g, plmax, pcmax, s, log_absorption, depoll, depolc)
    (1.35, 0.0, 0.4, 0.8, 0.3, 0.5, -1.0, 0.0, 0.0),
    (1.5, 0.0, -0.3, 1.0, -0.6, 0.0, -3.0, 0.3, 0.7),
    (2.2, 0.001, 0.7, 0.5, 0.2, -0.4, 0.5, 0.9, 0.1),
]


@pytest.mark.parametrize("n,k,g,pl,pc,s,la,dl,dc", CODE_WHITNEY)
def test_volume_code_whitney_matches_scatmech(n, k, g, pl, pc, s, la, dl, dc):
    peer = _scatmech(n, k, {"phase_function": "CodeWhitney_Phase_Function",
                            "phase_function.phase_function": "Henyey_Greenstein_Phase_Function",
                            "phase_function.phase_function.g": g, "phase_function.plmax": pl, "phase_function.pcmax": pc,
                            "phase_function.s": s, "phase_function.log_absorption": la, "phase_function.log_scattering": 0,
                            "depoll": dl, "depolc": dc})
    ti, tr, ps = _corpus()
    values = {"n": n, "k": k, "sigma": 0.2, "ks": 0.0, "w_vol": _albedo(la, k), "g_vol": g, "pl_vol": pl, "pc_vol": pc, "s_vol": s,
              "dl_vol": dl, "dc_vol": dc}
    ours = Model.from_string("specular+volume").evaluate(values, Geometry(ti, tr, 180.0 - ps), mueller=True).mueller
    theirs = _theirs(peer, ti, tr, ps)
    _assert_close(ours, theirs, f"Code-Whitney n={n} k={k} g={g}")
    # negative controls: the retardance term's sign, or the Fresnel transmission left out, fail the comparison
    flipped = Model.from_string("specular+volume").evaluate({**values, "pc_vol": -pc}, Geometry(ti, tr, 180.0 - ps), mueller=True).mueller
    assert np.max(np.abs(flipped / flipped[0, 0] - theirs / theirs[0, 0])) > 1e-3
    no_interface = Model.from_string("specular+volume").evaluate({**values, "n": 1.0 + 1e-9, "k": 0.0},
                                                                   Geometry(ti, tr, 180.0 - ps), mueller=True).mueller
    assert np.max(np.abs(no_interface[0, 0] / theirs[0, 0] - 1)) > 1e-2


def test_volume_rayleigh_matches_scatmech():
    """The Rayleigh phase matrix: SCATMECH's Code-Whitney matrix (plmax 1, pcmax 0) over its scalar
    Rayleigh_Phase_Function, which is 0.75 (1 + cos^2) per unit of 4 pi sr (it integrates to 4 pi, where
    SCATMECH's Henyey-Greenstein integrates to 1): spacepol's phase function 3 (1 + cos^2) / (16 pi) times 4 pi."""
    n, la = 1.35, -2.0
    peer = _scatmech(n, 0.0, {"phase_function": "CodeWhitney_Phase_Function",
                              "phase_function.phase_function": "Rayleigh_Phase_Function", "phase_function.plmax": 1,
                              "phase_function.pcmax": 0, "phase_function.log_absorption": la, "phase_function.log_scattering": 0})
    ti, tr, ps = _corpus()
    ours = Model.from_string("specular+volume_rayleigh").evaluate(
        {"n": n, "k": 0.0, "sigma": 0.2, "ks": 0.0, "w_ray": _albedo(la, 0.0)}, Geometry(ti, tr, 180.0 - ps), mueller=True).mueller
    _assert_close(ours * 4 * np.pi, _theirs(peer, ti, tr, ps), "Rayleigh")


def test_rayleigh_normalisation_agrees_with_a_small_sphere():
    """The normalisation of `volume_rayleigh` (its phase function integrates to 1) checked on SCATMECH's
    SphericalScatterer_Phase_Function with a sphere of radius 2 nm (size parameter 0.02): the exact Mie phase
    matrix, normalised by the scattering cross-section; it departs from Rayleigh's by O(x^2) ~ 1e-3."""
    n = 1.35
    peer = _scatmech(n, 0.0, {"phase_function": "SphericalScatterer_Phase_Function",
                              "phase_function.scatterer": "MieScatterer", "phase_function.scatterer.radius": 0.002,
                              "phase_function.scatterer.lambda": WAVELENGTH, "phase_function.scatterer.medium": "(1.35,0)",
                              "phase_function.scatterer.sphere": "(1.6,0)", "phase_function.volume_density": 1})
    ti, tr, ps = _corpus(size=60)
    theirs = _theirs(peer, ti, tr, ps)
    ours = Model.from_string("specular+volume_rayleigh").evaluate(
        {"n": n, "k": 0.0, "sigma": 0.2, "ks": 0.0, "w_ray": 1.0}, Geometry(ti, tr, 180.0 - ps), mueller=True).mueller
    np.testing.assert_allclose(ours[0, 0], theirs[0, 0], rtol=5e-3)
    np.testing.assert_allclose(ours / ours[0, 0], theirs / theirs[0, 0], atol=5e-3)
    assert np.max(np.abs(ours[0, 0] * 4 * np.pi / theirs[0, 0] - 1)) > 1  # the scale the other test corrects is real


@pytest.mark.parametrize("spec,values", [
    ("specular+volume", {"w_vol": 0.8, "g_vol": 0.5, "pl_vol": 0.7, "pc_vol": 0.4, "s_vol": 0.3, "dl_vol": 0.4, "dc_vol": 0.6}),
    ("specular+smith+subsurface+volume", {"rho_s": 0.7, "w_vol": 0.8, "g_vol": -0.2, "pl_vol": 0.9, "pc_vol": -0.3}),
    ("specular+volume_rayleigh", {"w_ray": 0.6}),
])
def test_volume_is_reciprocal(spec, values):
    """M(r -> i, -dphi) = Q M(i -> r, dphi)^T Q to 1e-9 (relative to M11), absorbing interface included."""
    ti, tr, ps = _corpus(size=200, seed=5)
    geometry = Geometry(ti, tr, 180.0 - ps)
    params = {"n": 1.45, "k": 0.02, "sigma": 0.3, "ks": 0.4, **values}
    model = Model.from_string(spec)
    forward = model.evaluate(params, geometry, mueller=True).mueller
    backward = model.evaluate(params, swapped(geometry), mueller=True).mueller
    np.testing.assert_allclose(backward, reciprocal_image(forward), rtol=0, atol=1e-9 * np.max(forward[0, 0]))
    assert model.effects[-1].reciprocal


def test_volume_polarizes_where_multiple_scattering_does_not():
    """What the term is for: out of the plane of incidence its light keeps a linear polarization that depends
    on the internal scattering angle, where `subsurface` light is polarized only by the exit transmission
    (in the exit plane: its normalised S2 is 0 in the (s, p) basis)."""
    ti, tr, ps = np.array([40.0]), np.array([50.0]), np.array([90.0])
    base = {"n": 1.35, "k": 0.0, "sigma": 0.2, "ks": 0.0}
    vol = Model.from_string("specular+volume").evaluate({**base, "w_vol": 1.0, "g_vol": 0.0, "pl_vol": 1.0, "pc_vol": 0.0},
                                                         Geometry(ti, tr, 180.0 - ps)).stokes
    sub = Model.from_string("specular+subsurface").evaluate({**base, "rho_s": 1.0}, Geometry(ti, tr, 180.0 - ps)).stokes
    assert abs(sub[2, 0] / sub[0, 0]) < 1e-12
    assert abs(vol[2, 0] / vol[0, 0]) > 0.05


@pytest.mark.parametrize("effect", ["volume", "volume_rayleigh", "phase_matrix"])
def test_the_stokes_vector_is_the_mueller_matrix_first_column(effect):
    """The Stokes-only program (DOP and BRDF data) builds its four elements apart from the Mueller matrix's sixteen,
    which the comparison with SCATMECH checks: the two must agree for random parameter sets of the prior."""
    model = Model.from_string(f"specular+{effect}")
    rng = np.random.default_rng(5)
    params = {p.name: rng.uniform(*p.prior.bounds, 8) for p in model.parameters}
    ti, tr, ps = _corpus(120)
    geometry = Geometry(ti, tr, 180.0 - ps)
    stokes = model.evaluate(params, geometry).stokes
    mueller = model.evaluate(params, geometry, mueller=True).mueller
    assert np.all(np.isfinite(stokes)) and np.all(stokes[0] > 0)
    np.testing.assert_allclose(stokes, mueller[:, 0], rtol=1e-12, atol=1e-14 * float(np.max(stokes[0])))
