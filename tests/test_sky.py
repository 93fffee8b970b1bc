"""Sky: the sun from astropy, Rayleigh and Berry-Dennis-Lee skies, checked by vectors."""

import numpy as np
import pytest

from spacepol.skylight.directions import fold_axial, local_frame, unit_vector
from spacepol.skylight.neutral_points import BerryDennisLeeSky
from spacepol.skylight.rayleigh import RayleighSky, paper_aop
from spacepol.skylight.sun import sun_position
from cli_runner import run_cli


def test_sun_at_changchun_on_16_december_2020():
    """ERRATA: 43 deg 8' N, 125 deg 32' E, 2020-12-16 11:42 UTC+8 -> zenith 66.49, azimuth 182.12 (the paper's
    29 deg 30' / -4 deg 32' is wrong for that date)."""
    sun = sun_position(43 + 8 / 60, 125 + 32 / 60, "2020-12-16T11:42:00+08:00")
    assert sun.zenith_deg == pytest.approx(66.49, abs=0.05)
    assert sun.azimuth_deg == pytest.approx(182.12, abs=0.05)


def test_sun_at_an_equinox_noon_stands_at_the_latitude():
    """2021-03-20 (equinox 09:37 UTC): at 45 deg N, 0 deg E the highest sun of the day is at zenith
    45 deg (declination ~0; it moves 0.4 deg/day) due south. Negative control: a day later in June it is not."""
    best = min((sun_position(45.0, 0.0, f"2021-03-20T12:{m:02d}:00Z") for m in range(0, 20)), key=lambda s: s.zenith_deg)
    assert best.zenith_deg == pytest.approx(45.0, abs=0.1)
    assert best.azimuth_deg == pytest.approx(180.0, abs=0.5)
    june = sun_position(45.0, 0.0, "2021-06-21T12:02:00Z")
    assert abs(june.zenith_deg - 45.0) > 20


def test_time_without_offset_is_refused():
    from spacepol.errors import SpacepolError

    with pytest.raises(SpacepolError, match="UTC offset"):
        sun_position(45, 0, "2021-03-20T12:00")


SUN = (50.0, 140.0)


def _random_sky(n=3000, seed=1):
    rng = np.random.default_rng(seed)
    return np.degrees(np.arccos(rng.uniform(0.02, 1.0, n))), rng.uniform(0, 360, n)


def test_rayleigh_dop_is_p_max_at_90_deg_from_the_sun_and_zero_at_sun_and_anti_sun():
    sky = RayleighSky(p_max=0.75)
    s = unit_vector(*SUN)
    # directions 90 deg from the sun: the great circle with axis s
    a = np.cross(s, [0, 0, 1.0])
    a /= np.linalg.norm(a)
    b = np.cross(s, a)
    t = np.linspace(0, 2 * np.pi, 50)
    ring = np.outer(np.cos(t), a) + np.outer(np.sin(t), b)
    ring = ring[ring[:, 2] > 0]
    zen, az = np.degrees(np.arccos(ring[:, 2])), np.degrees(np.arctan2(ring[:, 0], ring[:, 1]))
    assert np.allclose(sky.dop(zen, az, SUN), 0.75, atol=1e-12)
    assert sky.dop(*SUN, SUN) == pytest.approx(0.0, abs=1e-12)
    assert sky.dop(180 - SUN[0], SUN[1] + 180, SUN) == pytest.approx(0.0, abs=1e-12)  # anti-sun
    zen, az = _random_sky()
    assert np.all((sky.dop(zen, az, SUN) >= 0) & (sky.dop(zen, az, SUN) <= 0.75 + 1e-12))


def test_rayleigh_e_vector_is_perpendicular_to_the_scattering_plane():
    """Rebuild the E-vector from the reported AoP in the local frame and check it by vectors:
    perpendicular to the sun direction and to the view direction (the scattering plane's normal)."""
    sky = RayleighSky()
    zen, az = _random_sky()
    chi = np.radians(sky.aop(zen, az, SUN))
    up, east = local_frame(zen, az)
    e = np.cos(chi)[:, None] * up + np.sin(chi)[:, None] * east
    v, s = unit_vector(zen, az), unit_vector(*SUN)
    assert np.max(np.abs(e @ s)) < 1e-12 and np.max(np.abs(np.sum(e * v, axis=1))) < 1e-12
    # negative control: an AoP off by 10 deg is not perpendicular
    e_bad = np.cos(chi + 0.17)[:, None] * up + np.sin(chi + 0.17)[:, None] * east
    assert np.max(np.abs(e_bad @ s)) > 0.1


def test_paper_eq30_needs_zenith_angles():
    """Eq 30 with zenith angles equals the vector AoP; read with altitudes (as eqs 26-27) it is far off."""
    sky = RayleighSky()
    zen, az = _random_sky()
    good = paper_aop(zen, az, *SUN)
    assert np.max(np.abs(fold_axial(good - sky.aop(zen, az, SUN)))) < 1e-9
    wrong = paper_aop(90 - zen, az, 90 - SUN[0], SUN[1])
    assert np.median(np.abs(fold_axial(wrong - sky.aop(zen, az, SUN)))) > 5


def test_berry_dennis_lee_reduces_to_rayleigh_and_has_four_neutral_points():
    zen, az = _random_sky()
    for sun in (SUN, (75.0, 200.0), (5.0, 10.0)):
        flat = BerryDennisLeeSky(p_max=0.8, delta_deg=0.0)
        ray = RayleighSky(p_max=0.8)
        assert np.max(np.abs(flat.dop(zen, az, sun) - ray.dop(zen, az, sun))) < 1e-12
        assert np.max(np.abs(fold_axial(flat.aop(zen, az, sun) - ray.aop(zen, az, sun)))) < 1e-8
    sky = BerryDennisLeeSky(p_max=0.8, delta_deg=20.0)
    points = sky.neutral_points((70.0, 180.0))
    assert points["babinet"] == pytest.approx((50.0, 180.0)) and points["brewster"] == pytest.approx((90.0, 180.0))
    for z, a in points.values():
        assert sky.dop(z, a, (70.0, 180.0)) < 1e-12
    # Rayleigh (delta = 0) has polarization there: the zeros are what single scattering misses
    assert RayleighSky(0.8).dop(*points["babinet"], (70.0, 180.0)) > 0.04  # 0.8 sin^2 20 / (1 + cos^2 20) = 0.050


def _aop_winding(sky, centre, sun, radius=2.0):
    """Total turn of the AoP (an axis, unwrapped modulo 180) around a small loop about ``centre``."""
    c = unit_vector(*centre)
    a = np.cross(c, [1.0, 0, 0]) if abs(c[0]) < 0.9 else np.cross(c, [0, 1.0, 0])
    a /= np.linalg.norm(a)
    b = np.cross(c, a)
    t = np.linspace(0, 2 * np.pi, 721)
    r = np.radians(radius)
    loop = np.cos(r) * c + np.sin(r) * (np.outer(np.cos(t), a) + np.outer(np.sin(t), b))
    zen, az = np.degrees(np.arccos(loop[:, 2])), np.degrees(np.arctan2(loop[:, 0], loop[:, 1]))
    # compare against a fixed 3-D reference (the AoP's own frame turns around the loop): angle of
    # the E-vector projected on the loop's tangent plane basis (a, b)
    chi = np.radians(sky.aop(zen, az, sun))
    up, east = local_frame(zen, az)
    e = np.cos(chi)[:, None] * up + np.sin(chi)[:, None] * east
    angle = np.degrees(np.arctan2(e @ b, e @ a))
    step = fold_axial(np.diff(angle))
    return float(np.sum(step))


def test_singularity_indices_sun_plus_one_neutral_points_plus_half():
    """Rayleigh: the polarization pattern turns by 360 deg around the sun (index +1); BDL splits it
    into two points of index +1/2 (180 deg each) -- checked at Babinet and Brewster."""
    sun = (60.0, 150.0)
    assert abs(_aop_winding(RayleighSky(), sun, sun)) == pytest.approx(360.0, abs=1.0)
    bdl = BerryDennisLeeSky(0.8, 15.0)
    for name in ("babinet", "brewster"):
        assert abs(_aop_winding(bdl, bdl.neutral_points(sun)[name], sun)) == pytest.approx(180.0, abs=1.0)


def test_sky_command_writes_sky_json_and_maps(tmp_path):
    import json

    out = tmp_path / "sky"
    r = run_cli("sky", "--lat", "43.1333", "--lon", "125.5333", "--time",
                "2020-12-16T11:42+08:00", "--direction", "60,101.47", "--model", "berry-dennis-lee", "--out", out)
    assert r.returncode == 0, r.stderr
    report = json.loads((out / "sky.json").read_text())
    assert report["sun"]["zenith_deg"] == pytest.approx(66.49, abs=0.05)
    assert report["sun"]["azimuth_deg"] == pytest.approx(182.12, abs=0.05)
    d = report["directions"][0]
    assert d["dop"] == pytest.approx(float(BerryDennisLeeSky(0.8, 20).dop(60, 101.47, (report["sun"]["zenith_deg"],
                                                                                          report["sun"]["azimuth_deg"]))))
    assert set(report["neutral_points"]) == {"babinet", "brewster", "arago", "fourth"}
    assert report["projections"]["stereographic"]["max_angular_distortion_deg"] < 1e-9
    for name in ("sky_maps.png", "projections.png"):
        assert (out / name).stat().st_size > 0
    bad = run_cli("sky", "--lat", "43", "--lon", "125", "--time",
                  "2020-12-16T11:42+08:00", "--direction", "100,0", "--out", tmp_path / "bad")
    assert bad.returncode == 2 and "zenith angle must lie in [0, 90]" in bad.stderr and not (tmp_path / "bad").exists()
