"""The specular Mueller matrix against NIST SCATMECH and Beckmann+Smith against Mitsuba 3.

Both are independent implementations: SCATMECH's Facet_BRDF_Model (Germer) with Gaussian
slopes s = sqrt(2) sigma, and Mitsuba 3's ``roughconductor`` (Beckmann, alpha = sqrt(2) sigma)
in the ``scalar_spectral_polarized`` variant.
"""

import numpy as np
import pytest

from spacepol.physics import Geometry, Model
from spacepol.physics import facets
from spacepol.physics.effects.smith import Smith
from spacepol.physics.fresnel import hemispherical_internal_reflectance
from internal_reflectance import scatmech_grid, walton

# (theta_i, theta_r, phi_s) in degrees, SCATMECH's phi_s = 0 is the specular direction,
# which is dphi = 180 - phi_s in spacepol's convention.
GEOMETRIES = [
    (30.0, 40.0, 30.0), (10.0, 70.0, -45.0), (60.0, 20.0, 120.0), (45.0, 45.0, 0.0),
    (75.0, 75.0, 5.0), (0.0, 30.0, 60.0), (20.0, 0.0, 0.0), (50.0, 35.0, -170.0),
    (85.0, 60.0, 90.0), (5.0, 5.0, 179.0),
]
MATERIALS = [(1.24, 6.6), (1.405, 0.2289), (1.5, 0.0), (1.58, 15.7)]
# SCATMECH reads parameters as text with 6 significant digits: use an s it can hold exactly.
SLOPE_S = 0.3


@pytest.mark.parametrize("n,k", MATERIALS)
def test_specular_mueller_matches_scatmech(n, k):
    from pySCATMECH.brdf import BRDF_Model

    peer = BRDF_Model("Facet_BRDF_Model", {
        "lambda": 0.633, "substrate": f"({n},{k})", "type": 0,
        "sdf": "Gaussian_Slope_Distribution_Function", "sdf.s": SLOPE_S,
    })
    ti, tr, ps = np.array(GEOMETRIES).T
    geometry = Geometry(ti, tr, 180.0 - ps)
    ours = Model.from_string("specular").evaluate(
        {"n": n, "k": k, "sigma": SLOPE_S / np.sqrt(2), "ks": 1.0}, geometry, mueller=True
    ).mueller
    for j, (a, b, c) in enumerate(GEOMETRIES):
        theirs = np.array(peer.MuellerBRDF(np.radians(a), np.radians(b), np.radians(c)))
        scale = abs(theirs[0, 0])
        assert scale > 0
        np.testing.assert_allclose(ours[:, :, j], theirs, rtol=0, atol=1e-6 * scale,
                                   err_msg=f"geometry {GEOMETRIES[j]}, N = {n}+{k}i")


def test_scatmech_comparison_detects_a_sign_error():
    """Negative control: the comparison notices a wrong eta sign (the arccos-only eqs 4-5)."""
    from pySCATMECH.brdf import BRDF_Model

    peer = BRDF_Model("Facet_BRDF_Model", {
        "lambda": 0.633, "substrate": "(1.24,6.6)", "type": 0,
        "sdf": "Gaussian_Slope_Distribution_Function", "sdf.s": SLOPE_S,
    })
    a, b, c = 30.0, 40.0, 30.0
    mirrored = Geometry(np.array([a]), np.array([b]), np.array([180.0 + c]))  # sign of sin(dphi) flipped
    ours = Model.from_string("specular").evaluate(
        {"n": 1.24, "k": 6.6, "sigma": SLOPE_S / np.sqrt(2), "ks": 1.0}, mirrored, mueller=True
    ).mueller[:, :, 0]
    theirs = np.array(peer.MuellerBRDF(np.radians(a), np.radians(b), np.radians(c)))
    assert np.max(np.abs(ours - theirs)) > 1e-3 * theirs[0, 0]
    assert ours[0, 0] == pytest.approx(theirs[0, 0], rel=1e-6)  # intensity can't tell, S2 can


MITSUBA_GEOMETRIES = [
    (30.0, 40.0, 150.0), (10.0, 70.0, 200.0), (60.0, 20.0, 60.0), (45.0, 45.0, 180.0),
    (75.0, 80.0, 170.0), (0.5, 30.0, 120.0), (20.0, 0.5, 180.0), (50.0, 35.0, 10.0),
    (85.0, 60.0, 90.0), (70.0, 70.0, 185.0), (80.0, 85.0, 175.0), (40.0, 75.0, 160.0),
]


def _mitsuba_eval(n, k, sigma, geometries):
    import mitsuba as mi

    mi.set_variant("scalar_spectral_polarized")
    bsdf = mi.load_dict({
        "type": "roughconductor", "distribution": "beckmann", "alpha": float(np.sqrt(2) * sigma),
        "eta": n, "k": k, "sample_visible": False,
    })
    ctx = mi.BSDFContext()
    out = []
    for ti, tr, dphi in geometries:
        si = mi.SurfaceInteraction3f()
        si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
        si.wavelengths = [550.0, 600.0, 650.0, 700.0]
        a, b, phi_r = np.radians(ti), np.radians(tr), -np.radians(dphi)
        si.wi = mi.Vector3f(np.sin(a), 0.0, np.cos(a))
        wo = mi.Vector3f(np.sin(b) * np.cos(phi_r), np.sin(b) * np.sin(phi_r), np.cos(b))
        m = np.array(bsdf.eval(ctx, si, wo))[..., 0] / np.cos(b)  # Mitsuba returns f * cos(theta_o)
        out.append(m)
    return np.array(out)


def _subset(prediction, mask):
    from spacepol.physics.model import Prediction

    return Prediction(stokes=prediction.stokes[:, mask], dop=prediction.dop[mask])


class _WalterSmith(Smith):
    """Smith with the rational G1 that Mitsuba uses, to compare like with like."""

    beckmann_g1 = staticmethod(facets.smith_g1_beckmann_walter)


@pytest.mark.parametrize("n,k,sigma", [(1.24, 6.6, 0.2), (1.58, 15.7, 0.1), (0.2, 3.5, 0.35)])
def test_beckmann_smith_matches_mitsuba(n, k, sigma):
    ti, tr, dphi = np.array(MITSUBA_GEOMETRIES).T
    geometry = Geometry(ti, tr, dphi)
    theirs = _mitsuba_eval(n, k, sigma, MITSUBA_GEOMETRIES)
    params = {"n": n, "k": k, "sigma": sigma, "ks": 1.0}
    exact = Model.from_string("specular+smith").evaluate(params, geometry)
    # Far from the lobe Mitsuba (float32) sets D < 1e-20 to 0; ours is tiny there too.
    usable = theirs[:, 0, 0] > 1e-30
    assert usable.sum() >= 8
    assert np.all(exact.brdf[~usable] < 1e-18)
    theirs, exact = theirs[usable], _subset(exact, usable)
    geometry = Geometry(ti[usable], tr[usable], dphi[usable])
    their_brdf = theirs[:, 0, 0]
    their_dop = np.sqrt(theirs[:, 1, 0] ** 2 + theirs[:, 2, 0] ** 2 + theirs[:, 3, 0] ** 2) / their_brdf

    np.testing.assert_allclose(exact.dop, their_dop, rtol=0, atol=1e-4)

    like_mitsuba = Model(["specular", _WalterSmith]).evaluate(params, geometry)
    np.testing.assert_allclose(like_mitsuba.brdf, their_brdf, rtol=1e-3)
    # Our exact Smith differs from the rational fit by no more than its documented 0.35 %
    # per G1 factor (two factors), and the exact one is what `smith` uses.
    assert np.max(np.abs(exact.brdf / their_brdf - 1)) < 2 * 0.0035 + 1e-3


def test_walter_fit_is_close_to_exact_smith():
    tan = np.tan(np.radians(np.linspace(0.1, 89.5, 400)))
    for var in (0.005, 0.02, 0.08, 0.3):
        exact = facets.smith_g1_beckmann(tan, var)
        fit = facets.smith_g1_beckmann_walter(tan, var)
        assert np.max(np.abs(fit - exact) / np.maximum(exact, 1e-3)) < 0.0035


def test_internal_reflectance_is_waltons_closed_form():
    """The subsurface term's recycled share: the internal hemispherical reflectance equals Walton's closed form to
    1e-12 from n 1.02 to 4, and it is smooth in n (central differences at two steps agree with the closed form's
    slope), where a fixed grid of angles has a cusp each time the critical angle crosses a node (the control)."""
    n = np.linspace(1.02, 4.0, 150)
    ours = np.asarray(hemispherical_internal_reflectance(n))
    np.testing.assert_allclose(ours, walton(n), rtol=0, atol=1e-12)
    centre = np.array([1.016, 1.2, 1.35, 1.5])
    exact = (walton(centre + 1e-6) - walton(centre - 1e-6)) / 2e-6
    for h in (1e-4, 1e-7):
        slope = (np.asarray(hemispherical_internal_reflectance(centre + h))
                 - np.asarray(hemispherical_internal_reflectance(centre - h))) / (2 * h)
        np.testing.assert_allclose(slope, exact, rtol=1e-4, err_msg=f"step {h:g}")
    grid = (scatmech_grid(centre + 1e-7) - scatmech_grid(centre - 1e-7)) / 2e-7
    assert np.max(np.abs(grid / exact - 1)) > 0.1, f"the grid's slopes {grid} should miss the closed form's {exact}"


@pytest.mark.parametrize("n,albedo", [(1.5, 0.5), (1.35, 0.9), (2.2, 0.2)])
def test_subsurface_mueller_matches_scatmech(n, albedo):
    """`subsurface` against SCATMECH's Diffuse_Subsurface_BRDF_Model (Lambertian scatterer under a smooth
    interface, Fresnel in and out, internal reflections recycled): every Mueller element to 1e-6."""
    from pySCATMECH.brdf import BRDF_Model

    peer = BRDF_Model("Diffuse_Subsurface_BRDF_Model", {
        "lambda": 0.633, "substrate": f"({n},0)", "type": 0, "reflectance": "Table_Reflectance", "reflectance.table": albedo})
    ti, tr, ps = np.array(GEOMETRIES).T
    ours = Model.from_string("specular+subsurface").evaluate(
        {"n": n, "k": 0.0, "sigma": 0.2, "ks": 0.0, "rho_s": albedo}, Geometry(ti, tr, 180.0 - ps), mueller=True).mueller
    # SCATMECH averages the internal reflectance on a 0.2 deg grid (off by up to 3e-4 of the exact average that
    # spacepol computes, ``test_internal_reflectance_is_waltons_closed_form``): its recycled share, used here
    as_scatmech = ours * (1 - hemispherical_internal_reflectance(n) * albedo) / (1 - scatmech_grid(n) * albedo)
    for j, (a, b, c) in enumerate(GEOMETRIES):
        theirs = np.array(peer.MuellerBRDF(np.radians(a), np.radians(b), np.radians(c)))
        np.testing.assert_allclose(as_scatmech[:, :, j], theirs, rtol=0, atol=1e-6 * theirs[0, 0], err_msg=f"geometry {GEOMETRIES[j]}")
    # negative controls: without the recycled light, or without the 1/n^2, the comparison fails
    no_recycling = Model.from_string("specular+polarized_diffuse").evaluate(
        {"n": n, "k": 0.0, "sigma": 0.2, "ks": 0.0, "rho_pd": albedo / n**2}, Geometry(ti, tr, 180.0 - ps), mueller=True).mueller
    theirs = np.array(peer.MuellerBRDF(*np.radians(GEOMETRIES[0])))
    assert abs(no_recycling[0, 0, 0] - theirs[0, 0]) > 1e-3 * theirs[0, 0]
    # the declared twin: polarized_diffuse with rho_pd = rho_s / (n^2 (1 - rho_i rho_s)) is the same matrix
    rho_pd = albedo / (n**2 * (1 - hemispherical_internal_reflectance(n) * albedo))
    twin = Model.from_string("specular+polarized_diffuse").evaluate(
        {"n": n, "k": 0.0, "sigma": 0.2, "ks": 0.0, "rho_pd": rho_pd}, Geometry(ti, tr, 180.0 - ps), mueller=True).mueller
    np.testing.assert_allclose(twin, ours, rtol=1e-12, atol=1e-15)
