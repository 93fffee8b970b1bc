"""The target's light over a pass: a faceted Lambertian sphere against Lambert's analytic sphere,
the polarization of specular reflection perpendicular to the sun - target - observer plane on the sky, and the
sun's band irradiance against the solar constant."""

import numpy as np
import pytest

from spacepol.detect.target import solar_band, target_light
from spacepol.orbit import Face, pass_geometry, read_tle
from spacepol.paths import bundled
from spacepol.physics.geometry import Geometry
from spacepol.physics.model import Model

SITE = (43 + 8 / 60, 125 + 32 / 60, 200.0)
START, END = "2014-01-21T00:33:30Z", "2014-01-21T00:39:00Z"
BAND = (1.5, 1.8)


@pytest.fixture(scope="module")
def tle():
    return read_tle(bundled("tle", "iss_zarya_2014-01-20.tle"))


def sphere_faces(radius_m: float, n: int) -> list[Face]:
    """A sphere as ``n`` inertial faces of equal area (a Fibonacci lattice of normals)."""
    k = np.arange(n) + 0.5
    z = 1 - 2 * k / n
    phi = np.pi * (1 + 5**0.5) * k
    r = np.sqrt(1 - z**2)
    area = 4 * np.pi * radius_m**2 / n
    return [Face(f"f{i}", area, "inertial", (r[i] * np.cos(phi[i]), r[i] * np.sin(phi[i]), z[i])) for i in range(n)]


def test_the_sun_in_a_wide_band_gives_the_solar_constant():
    """The black body over 0.1-100 um holds all but 0.1 % of sigma T^4 (R/au)^2 = 1361 W m^-2 (the measured solar
    constant is 1361 W m^-2, Kopp & Lean 2011); 1.5-1.8 um holds about 5 % of it."""
    total, _ = solar_band(0.1, 100.0)
    assert total == pytest.approx(1361.0, rel=0.01)
    band, photons = solar_band(*BAND)
    assert 0.03 < band / total < 0.08
    assert photons == pytest.approx(band / (6.62607015e-34 * 299792458.0 / 1.65e-6), rel=0.02)  # ~ E / (hc / lambda_mid)


def test_a_faceted_lambertian_sphere_matches_lamberts_sphere(tle):
    """Flux of a Lambertian sphere of radius a, albedo rho: F = (2/3) rho E a^2 / (pi R^2) [sin a + (pi - a) cos a]
    at phase angle a. 4,000 faces reach it within 0.5 %; the control: a sphere of half the faces' albedo is 50 % off."""
    rho, radius = 0.6, 2.0
    g = pass_geometry(tle, SITE, START, END, step_s=30.0, faces=sphere_faces(radius, 4000))
    light = target_light(g, Model.from_string("lambertian"), {"rho_l": rho}, BAND)
    irradiance, _ = solar_band(*BAND)
    a = np.radians(g.phase_angle_deg)
    expected = 2 / 3 * rho * irradiance * radius**2 / (np.pi * (g.range_km * 1e3) ** 2) * (np.sin(a) + (np.pi - a) * np.cos(a))
    seen = g.visible
    ratio = light.stokes_w_m2[0, 0, seen] / expected[seen]
    assert np.abs(ratio - 1).max() < 0.005, ratio
    assert np.allclose(light.dolp[0, seen], 0.0, atol=1e-9)  # Lambertian light is unpolarized
    half = target_light(g, Model.from_string("lambertian"), {"rho_l": rho / 2}, BAND)
    assert np.abs(half.stokes_w_m2[0, 0, seen] / expected[seen] - 1).min() > 0.4


def test_specular_light_is_polarized_perpendicular_to_the_scattering_plane_on_the_sky(tle):
    """Unpolarized sunlight reflected by facets leaves polarized along k_in x k_out, perpendicular to the plane of
    sun, target and observer, whatever each face's own basis: the AoP of the summed faces on the sky (from the
    horizontal, towards the vertical) is that direction's, and the DoLP is between 0 and 1 and not 0."""
    faces = sphere_faces(1.0, 800)
    g = pass_geometry(tle, SITE, START, END, step_s=30.0, faces=faces)
    draws = {"n": np.array([1.5, 1.7]), "k": np.array([0.0, 0.1]), "sigma": np.array([0.2, 0.3]), "ks": np.array([1.0, 1.0])}
    light = target_light(g, Model.from_string("specular+smith"), draws, BAND)
    seen = g.visible
    d = g.to_observer_unit
    up = g.position_km + g.range_km * d
    up /= np.linalg.norm(up, axis=0)
    s_ref = np.cross(up.T, d.T).T
    s_ref /= np.linalg.norm(s_ref, axis=0)
    p_ref = np.cross(d.T, s_ref.T).T
    e = np.cross(g.sun_unit.T, d.T).T  # the normal of the scattering plane
    expected = np.degrees(np.arctan2(np.sum(e * p_ref, axis=0), np.sum(e * s_ref, axis=0)))
    for j in range(2):
        diff = (light.aop_deg[j, seen] - expected[seen] + 90.0) % 180.0 - 90.0
        assert np.abs(diff).max() < 0.5, diff
        assert np.all((light.dolp[j, seen] > 0.01) & (light.dolp[j, seen] < 1.0))
    # the control: the AoP 90 deg off (polarization in the scattering plane) is far from it
    assert np.abs((light.aop_deg[0, seen] - (expected[seen] + 90.0) + 90.0) % 180.0 - 90.0).min() > 45.0


def test_the_chain_gives_contrasts_target_dop_at_table_3s_geometry():
    """Table 3's target: theta_i 30 deg, dphi 180 deg, theta_r over [0, 80] deg. One face seen along those directions
    through the pass chain (its Stokes rotated into the sky basis and back to a DoLP) gives the DOP that ``contrast``
    computes for the same posterior draws (``detect.contrast.target_dop_grid``), to rounding."""
    from datetime import datetime, timezone

    from spacepol.detect.contrast import target_dop_grid
    from spacepol.detect.scenario import default_scenario
    from spacepol.orbit.pass_geometry import PassGeometry, face_angles

    scenario = default_scenario()
    theta_r = np.linspace(0.5, 79.5, 12)
    ti = np.radians(30.0)
    n = len(theta_r)
    normal = np.array([0.0, 0.0, 1.0])
    sun = np.repeat(np.array([np.sin(ti), 0.0, np.cos(ti)])[:, None], n, axis=1)
    view = np.stack([-np.sin(np.radians(theta_r)), np.zeros(n), np.cos(np.radians(theta_r))])  # dphi = 180
    position = np.repeat(np.array([7000.0, 0.0, 0.0])[:, None], n, axis=1)
    face = Face("plate", 1.0, "inertial", tuple(normal))
    a_i, a_r, dphi = face_angles(np.repeat(normal[:, None], n, axis=1), sun, view)
    assert np.allclose(a_i, 30.0) and np.allclose(a_r, theta_r) and np.allclose(np.abs(dphi), 180.0)
    times = [datetime(2014, 1, 21, tzinfo=timezone.utc)] * n
    geometry = PassGeometry("plate", (0.0, 0.0, 0.0), times, np.zeros(n), np.full(n, 45.0), np.full(n, 1000.0),
                            np.zeros(n), np.full(n, 30.0), np.ones(n, bool), np.degrees(np.arccos(np.sum(sun * view, axis=0))),
                            position, np.repeat(np.array([[0.0], [7.5], [0.0]]), n, axis=1), sun, view, [face],
                            a_i[:, None], a_r[:, None], dphi[:, None])
    model = Model.from_string("specular+shadowing+body")
    draws = {"n": np.array([1.4, 1.5, 1.7]), "k": np.array([0.0, 0.1, 0.5]), "sigma": np.array([0.2, 0.25, 0.35]),
             "ks": np.array([0.6, 0.5, 0.9]), "rho_d": np.array([0.3, 0.1, 0.05])}
    light = target_light(geometry, model, draws, BAND)
    scenario.target.update(theta_r_low_deg=float(theta_r[0]), theta_r_high_deg=float(theta_r[-1]))
    grid_theta_r, dop = target_dop_grid(model, draws, scenario)
    expected = np.stack([np.interp(theta_r, grid_theta_r, row) for row in dop])
    assert np.abs(light.dolp - expected).max() < 2e-3  # the contrast grid's linear interpolation in theta_r
    exact = model.dop(draws, Geometry(np.full(n, 30.0), theta_r, np.full(n, 180.0)))
    assert np.abs(light.dolp - exact).max() < 1e-9


def test_the_chain_gives_contrasts_sky_dop_at_table_3s_directions():
    """Table 3's sky: the pass chain's sky DoLP (``observation.sky_dolp_at``, from a pass geometry's view and sun) at
    the paper's two directions, at the scenario's site and time, equals ``contrast``'s sky DOP for the same P_max
    (its draws at P_max fixed), at both ends of the scenario's P_max range. The control: the sun's azimuth off by
    the paper's erroneous value (ERRATA) changes it."""
    from datetime import datetime

    from spacepol.detect.contrast import _draw_sky
    from spacepol.detect.observation import sky_dolp_at
    from spacepol.detect.scenario import default_scenario
    from spacepol.orbit.pass_geometry import PassGeometry
    from spacepol.skylight.sun import sun_position

    scenario = default_scenario()
    site = scenario.site
    sun = sun_position(site["lat_deg"], site["lon_deg"], site["time"])
    cases = scenario.cases
    n = len(cases)
    zeros = np.zeros((3, n))
    geometry = PassGeometry("Table 3", (site["lat_deg"], site["lon_deg"], 0.0), [datetime.fromisoformat(site["time"])] * n,
                            np.array([c["azimuth_deg"] for c in cases]), np.array([90.0 - c["zenith_deg"] for c in cases]),
                            np.full(n, 1000.0), np.full(n, sun.azimuth_deg), np.full(n, 90.0 - sun.zenith_deg),
                            np.ones(n, bool), np.zeros(n), zeros, zeros, zeros, zeros)
    rng = np.random.default_rng(0)
    for p_max in (scenario.sky["p_max_low"], scenario.sky["p_max_high"]):
        chain = sky_dolp_at(geometry, p_max)
        expected = [float(_draw_sky(scenario, case, sun, rng, 3, p_max)[0]) for case in cases]
        assert np.allclose(chain, expected, rtol=1e-12, atol=1e-12), (chain, expected)
        assert np.all((chain > 0.05) & (chain < p_max))
    geometry.sun_azimuth_deg = np.full(n, -(4 + 32 / 60))  # the paper's stated azimuth
    assert np.abs(sky_dolp_at(geometry, p_max) - expected).max() > 0.01


def test_a_face_of_its_own_fixed_material_adds_its_light_and_ignores_the_runs_draws(tle, tmp_path):
    """A panel of fixed aluminium-like parameters beside a body of the run's material: the target's Stokes flux is
    the sum of the two faces' alone, the panel's is the same for every draw and equals the run's model evaluated at
    those fixed values; a material with an unknown parameter is one line."""
    from spacepol.errors import ParameterError
    from spacepol.orbit import faces_from_toml, pass_geometry

    aluminium = {"model": "specular+smith", "n": 1.37, "k": 7.6, "sigma": 0.1, "ks": 0.9}
    window = ("2014-01-21T00:33:00Z", "2014-01-21T00:40:00Z", 30.0)
    body, panel = Face("body", 20.0, "nadir", (0, 0, 1)), Face("panel", 60.0, "sun", material=aluminium)
    model = Model.from_string("specular+shadowing+body")
    draws = {"n": np.array([1.4, 1.5, 1.6]), "rho_d": np.array([0.1, 0.2, 0.3])}

    def light(faces, m=model, d=draws):
        return target_light(pass_geometry(tle, SITE, *window, faces), m, d, BAND).stokes_w_m2

    both, alone = light([body, panel]), light([panel])
    assert np.abs(both - light([body]) - alone).max() <= 1e-12 * np.abs(both).max()
    assert np.abs(alone).max() > 0 and np.allclose(alone, alone[:, :1, :], rtol=1e-12, atol=0)
    as_run = light([Face("panel", 60.0, "sun")], Model.from_string("specular+smith"),
                   {k: v for k, v in aluminium.items() if k != "model"})
    assert np.allclose(alone[:, 0], as_run[:, 0], rtol=1e-12, atol=0)
    path = tmp_path / "target.toml"
    path.write_text('[[faces]]\nname = "panel"\narea_m2 = 4\norientation = "sun"\n'
                    'material = {model = "specular+smith", n = 1.4, roughness = 0.2}\n')
    face = faces_from_toml(path)[0]
    with pytest.raises(ParameterError, match="no parameter roughness"):
        light([face])
