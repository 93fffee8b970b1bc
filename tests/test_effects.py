"""Each effect changes the prediction the way its physics says."""

import numpy as np
import pytest

from spacepol.physics import Geometry, Model, facets, fresnel

PAPER = {"n": 1.405, "k": 0.2289, "sigma": 0.25, "ks": 0.6, "rho_d": 0.2}


def ev(spec, params, geometry, **kw):
    """Evaluate with the subset of ``params`` the model has (the model itself rejects unknown names)."""
    model = Model.from_string(spec)
    names = {p.name for p in model.parameters}
    return model.evaluate({k: v for k, v in params.items() if k in names}, geometry, **kw)


def in_plane(theta_i, theta_r, dphi=180.0, wavelength=0.633):
    ti, tr = np.broadcast_arrays(np.asarray(theta_i, float), np.asarray(theta_r, float))
    return Geometry(ti.ravel(), tr.ravel(), np.full(ti.size, dphi), np.full(ti.size, wavelength))


def test_specular_lobe_dop_is_fresnel_dop_at_the_facet_angle():
    g = in_plane(30.0, np.linspace(0, 85, 40))
    pred = ev("specular", PAPER, g)
    r_s, r_p = fresnel.power(PAPER["n"], PAPER["k"], g.cos_beta, g.sin2_beta, g.sin_tan_beta)
    np.testing.assert_allclose(pred.dop, np.abs(r_s - r_p) / (r_s + r_p), rtol=1e-12)
    # A narrow lobe peaks at the mirror direction (a wide one peaks off-specular, towards grazing,
    # through 1/(cos ti cos tr): the off-specular peak of Torrance-Sparrow).
    narrow = ev("specular", {**PAPER, "sigma": 0.05}, g)
    assert np.argmax(narrow.brdf) == np.argmin(np.abs(g.theta_r - 30.0))
    assert np.argmax(pred.brdf) == len(g.theta_r) - 1


def test_specular_albedo_at_normal_incidence_is_the_fresnel_reflectance():
    """Energy: integral of f cos(theta_r) d omega = R(0) for a narrow lobe (D normalised, eq 1)."""
    tr = np.linspace(0, np.pi / 2, 600)[1:-1]
    ph = np.linspace(-np.pi, np.pi, 721)
    T, P = np.meshgrid(tr, ph, indexing="ij")
    g = Geometry(np.zeros(T.size), np.degrees(T.ravel()), np.degrees(P.ravel()))
    f = ev("specular", {"n": 1.5, "k": 0.0, "sigma": 0.05, "ks": 1.0}, g).brdf
    integrand = (f * np.cos(T.ravel()) * np.sin(T.ravel())).reshape(T.shape)
    albedo = np.trapezoid(np.trapezoid(integrand, ph, axis=1), tr)
    assert albedo == pytest.approx(0.04, rel=0.01)  # ((1.5 - 1)/(1.5 + 1))^2


@pytest.mark.parametrize("name", ["beckmann", "ggx"])
@pytest.mark.parametrize("aniso", [False, True])
def test_distributions_are_normalised(name, aniso):
    """integral D cos(alpha) d omega_h = 1 over the hemisphere of facet normals (eq 1)."""
    a = np.linspace(0, np.pi / 2, 3001)[:-1]
    p = np.linspace(0, 2 * np.pi, 361)
    A, P = np.meshgrid(a, p, indexing="ij")
    tan2, sec4 = np.tan(A) ** 2, np.cos(A) ** -4
    if aniso:
        fn = facets.ggx_anisotropic if name == "ggx" else facets.beckmann_anisotropic
        D = fn(tan2, sec4, P, 0.1, 0.25, 30.0)
    else:
        fn = facets.ggx if name == "ggx" else facets.beckmann
        D = fn(tan2, sec4, 0.15)
    total = np.trapezoid(np.trapezoid(D * np.cos(A) * np.sin(A), p, axis=1), a)
    # GGX's tails reach alpha = 90 deg slowly; the grid resolves 1e-3.
    assert total == pytest.approx(1.0, abs=2e-3)


@pytest.mark.parametrize("shadow", ["shadowing", "smith"])
def test_shadowing_darkens_grazing_geometry_but_not_the_lobe_dop(shadow):
    g = in_plane(np.array([20.0, 70.0, 85.0]), np.array([20.0, 70.0, 85.0]))
    bare = ev("specular", PAPER, g)
    shadowed = ev(f"specular+{shadow}", PAPER, g)
    ratio = shadowed.brdf / bare.brdf
    assert np.all(ratio <= 1.0 + 1e-12)
    assert ratio[2] < ratio[1] < ratio[0]  # more shadowing towards grazing
    np.testing.assert_allclose(shadowed.dop, bare.dop, rtol=1e-12)


def test_paper_shadowing_is_continuous_through_the_specular_peak():
    tr = 40.0 + np.array([-1e-4, 0.0, 1e-4])
    g = in_plane(40.0, tr)
    G = ev("specular+shadowing", PAPER, g).brdf / ev("specular", PAPER, g).brdf
    assert np.ptp(G) < 1e-4


def test_body_adds_unpolarized_light():
    g = in_plane(30.0, np.linspace(0, 80, 17))
    without = ev("specular+shadowing", PAPER, g)
    with_body = ev("paper", PAPER, g)
    np.testing.assert_allclose(with_body.brdf - without.brdf, PAPER["rho_d"] * np.cos(np.radians(g.theta_r)) / np.pi)
    np.testing.assert_allclose(with_body.stokes[1:], without.stokes[1:])
    assert np.all(with_body.dop < without.dop)


def test_polarized_diffuse_raises_dop_at_grazing_exit_and_is_p_polarized():
    g = in_plane(20.0, np.array([10.0, 50.0, 80.0, 88.0]), dphi=0.0)  # backscatter side: no specular light
    params = {**PAPER, "n": 1.5, "k": 0.0, "rho_pd": 0.5}
    base = ev("paper", params, g)
    pd = ev("paper+polarized_diffuse", params, g)
    assert pd.dop[-1] > base.dop[-1] + 0.05
    assert np.all(np.diff(pd.dop) > 0)  # rises towards grazing exit
    only = ev("specular+polarized_diffuse", {**params, "ks": 0.0}, g)
    assert np.all(only.stokes[1] < 0)  # S1 < 0: polarized parallel to the exit plane
    # Atkinson & Hancock: diffuse DOP = (R_p - R_s)/(2 - R_s - R_p) in transmission terms at the exit angle
    r_s, r_p = fresnel.power(1.5, 0.0, g.cos_tr, 1 - g.cos_tr**2, (1 - g.cos_tr**2) / g.cos_tr)
    np.testing.assert_allclose(only.dop, (r_s - r_p) / (2 - r_s - r_p), rtol=1e-10)


def test_depolarization_scales_the_specular_dop():
    g = in_plane(30.0, np.linspace(0, 80, 9))
    bare = ev("specular", PAPER, g)
    dep = ev("specular+depolarization", {**PAPER, "d_spec": 0.3}, g)
    np.testing.assert_allclose(dep.dop, 0.7 * bare.dop, rtol=1e-12)
    np.testing.assert_allclose(dep.brdf, bare.brdf, rtol=1e-12)


def test_anisotropy_reduces_to_isotropic_and_rotates():
    rng = np.random.default_rng(3)
    g = Geometry(rng.uniform(0, 80, 30), rng.uniform(0, 80, 30), rng.uniform(-180, 180, 30))
    iso = ev("specular", PAPER, g)
    same = ev("specular+anisotropy", {**PAPER, "sigma_x": 0.25, "sigma_y": 0.25, "psi": 37.0}, g)
    np.testing.assert_allclose(same.stokes, iso.stokes, rtol=1e-12, atol=1e-300)
    a = ev("specular+anisotropy", {**PAPER, "sigma_x": 0.1, "sigma_y": 0.3, "psi": 0.0}, g)
    b = ev("specular+anisotropy", {**PAPER, "sigma_x": 0.3, "sigma_y": 0.1, "psi": 90.0}, g)
    np.testing.assert_allclose(a.stokes, b.stokes, rtol=1e-10, atol=1e-300)
    # a lobe narrow in x, wide in y: out of the plane there is more light than the isotropic narrow lobe
    out_of_plane = Geometry(np.array([30.0]), np.array([30.0]), np.array([120.0]))
    narrow = ev("specular", {**PAPER, "sigma": 0.1}, out_of_plane).brdf
    aniso = ev("specular+anisotropy", {**PAPER, "sigma_x": 0.1, "sigma_y": 0.3, "psi": 0.0}, out_of_plane).brdf
    assert aniso[0] > 2 * narrow[0]


def test_ggx_has_longer_tails_than_beckmann():
    g = in_plane(30.0, np.array([30.0, 85.0]), dphi=180.0)
    far = Geometry(np.array([30.0]), np.array([60.0]), np.array([0.0]))  # backscatter side
    beck = ev("specular", PAPER, far).brdf
    ggx = ev("specular+ggx", PAPER, far).brdf
    assert ggx[0] > 3 * beck[0]
    assert ev("specular+ggx", PAPER, g).brdf[0] > 0


def test_oxide_layer_of_zero_thickness_is_bare_and_oscillates_with_thickness():
    g = in_plane(50.0, 50.0)
    al = {"n": 1.24, "k": 6.6, "sigma": 0.2, "ks": 1.0}
    bare = ev("specular", al, g)
    zero = ev("specular+oxide_layer", {**al, "thickness_um": 0.0, "n_film": 1.65}, g)
    np.testing.assert_allclose(zero.stokes, bare.stokes, rtol=1e-12)
    d = np.linspace(0.0, 0.6, 121)
    dop = ev("specular+oxide_layer", {**al, "thickness_um": d, "n_film": 1.65}, g).dop[:, 0]
    assert np.ptp(dop) > 0.05
    # period of the interference: lambda / (2 n_f cos(theta_f)) at the facet angle (50 deg)
    cos_f = np.sqrt(1 - (np.sin(np.radians(50.0)) / 1.65) ** 2)
    period = 0.633 / (2 * 1.65 * cos_f)
    shifted = ev("specular+oxide_layer", {**al, "thickness_um": d + period, "n_film": 1.65}, g).dop[:, 0]
    np.testing.assert_allclose(shifted, dop, atol=1e-10)


def test_oxide_layer_without_wavelength_is_a_clear_error():
    from spacepol.errors import ParameterError

    g = Geometry(np.array([30.0]), np.array([30.0]), np.array([180.0]))
    with pytest.raises(ParameterError, match="wavelength"):
        ev("specular+oxide_layer", {}, g)


def test_angle_offset_shifts_the_curve():
    tr = np.linspace(0, 70, 15)
    delta = 2.0
    shifted = ev("paper+angle_offset", {**PAPER, "delta_deg": delta}, in_plane(30.0, tr))
    moved = ev("paper", PAPER, in_plane(30.0 + delta, tr + delta))
    np.testing.assert_allclose(shifted.stokes, moved.stokes, rtol=1e-12)
    assert np.max(np.abs(shifted.dop - ev("paper", PAPER, in_plane(30.0, tr)).dop)) > 1e-3


def test_angle_offset_vectorises_over_parameter_sets():
    g = in_plane(30.0, np.linspace(0, 70, 15))
    deltas = np.array([-1.5, 0.0, 2.0])
    batch = ev("paper+angle_offset", {**PAPER, "delta_deg": deltas}, g)
    assert batch.dop.shape == (3, 15)
    for i, d in enumerate(deltas):
        np.testing.assert_allclose(batch.stokes[:, i], ev("paper+angle_offset", {**PAPER, "delta_deg": d}, g).stokes, rtol=1e-12)


def test_extinction_scales_dop_and_keeps_intensity():
    g = in_plane(40.0, np.linspace(0, 80, 9))
    base = ev("paper", PAPER, g)
    ext = ev("paper+extinction", {**PAPER, "e": 0.8}, g)
    np.testing.assert_allclose(ext.dop, 0.8 * base.dop, rtol=1e-12)
    np.testing.assert_allclose(ext.brdf, base.brdf, rtol=1e-12)


def test_dop_bias_is_rician_on_average():
    g = in_plane(40.0, np.linspace(0, 80, 9))
    base = ev("paper", PAPER, g)
    biased = ev("paper+dop_bias", {**PAPER, "bias": 0.05}, g)
    np.testing.assert_allclose(biased.dop, np.sqrt(base.dop**2 + 0.05**2), rtol=1e-12)
    assert np.all(biased.dop > base.dop)


def test_lambertian_reflects_its_albedo_and_is_unpolarized():
    """Directional-hemispherical reflectance of rho_l/pi is rho_l at every incidence (quadrature over the
    hemisphere, independent of the model code); its light is unpolarized (S1 = S2 = 0 alone)."""
    import numpy as np

    from spacepol.physics import Geometry, Model

    model = Model.from_string("lambertian")
    tr, dphi = np.meshgrid(np.linspace(0.0, 89.9, 400), np.linspace(-180.0, 180.0, 181), indexing="ij")
    for ti in (0.0, 40.0, 80.0):
        g = Geometry(np.full(tr.size, ti), tr.ravel(), dphi.ravel())
        pred = model.evaluate({"rho_l": 0.37}, g)
        f = pred.brdf.reshape(tr.shape)
        integrand = f * np.cos(np.radians(tr)) * np.sin(np.radians(tr))
        albedo = np.trapezoid(np.trapezoid(integrand, np.radians(dphi[0]), axis=1), np.radians(tr[:, 0]))
        assert abs(albedo - 0.37) < 2e-3, (ti, albedo)
        assert np.all(pred.stokes[1:] == 0)


def test_a_length_one_array_is_one_set_shared_by_all_wherever_it_stands():
    """Parameter arrays of P values broadcast with length-1 arrays in any order of the model's parameters
    (n comes before k: a length-1 n used to be taken for P = 1); lengths that do not match are named."""
    from spacepol.errors import ParameterError

    model = Model.from_string("paper")
    g = Geometry(np.array([20.0, 40.0, 60.0]), np.array([10.0, 40.0, 70.0]), np.array([180.0, 180.0, 90.0]))
    shared = model.dop({"n": [1.5], "k": [0.1, 0.2]}, g)
    np.testing.assert_array_equal(shared, model.dop({"n": [1.5, 1.5], "k": [0.1, 0.2]}, g))
    np.testing.assert_allclose(model.evaluate({"k": [0.1, 0.2], "n": [1.5]}, g).dop, shared, rtol=1e-14, atol=1e-16)
    with pytest.raises(ParameterError, match=r"different lengths \(n: 3, k: 2\)"):
        model.dop({"n": [1.5, 1.6, 1.7], "k": [0.1, 0.2]}, g)
