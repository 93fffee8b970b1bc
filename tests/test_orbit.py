"""A satellite's pass: the project's geometry (skyfield's SGP4 and frames) against an independent
computation (the sgp4 package's TEME vectors taken to the site by astropy), the phase angle against the topocentric
directions, each face's angles, and a TLE file's errors."""

from datetime import timedelta

import astropy.units as u
import numpy as np
import pytest
from astropy.coordinates import ITRS, TEME, AltAz, CartesianDifferential, CartesianRepresentation, EarthLocation
from astropy.time import Time
from astropy.utils import iers
from sgp4.api import Satrec

from spacepol.errors import SpacepolError
from spacepol.orbit import Face, pass_geometry, read_tle
from spacepol.paths import bundled

SITE = (43 + 8 / 60, 125 + 32 / 60, 200.0)  # the paper's site (Changchun), 200 m
# a daytime pass of the ISS over the site, 9 h after the elements' epoch (local time about 08:55)
START, END = "2014-01-21T00:32:00Z", "2014-01-21T00:41:00Z"


@pytest.fixture(scope="module")
def tle():
    return read_tle(bundled("tle", "iss_zarya_2014-01-20.tle"))


def _enu(az_deg, el_deg):
    az, el = np.radians(az_deg), np.radians(el_deg)
    return np.array([np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.sin(el)])


def astropy_altaz(tle, times, site=SITE, shift_s: float = 0.0):
    """The satellite seen from the site: sgp4's TEME state, astropy's TEME -> ITRS, minus the site's ITRS position,
    -> AltAz (astropy's documented way for nearby objects: no aberration, no light deflection)."""
    sat = Satrec.twoline2rv(tle.line1, tle.line2)
    when = Time([t.replace(tzinfo=None) + timedelta(seconds=shift_s) for t in times], scale="utc")
    _, r, v = sat.sgp4_array(when.jd1, when.jd2)
    teme = TEME(CartesianRepresentation(r.T * u.km, differentials=CartesianDifferential(v.T * u.km / u.s)), obstime=when)
    loc = EarthLocation(lat=site[0] * u.deg, lon=site[1] * u.deg, height=site[2] * u.m)
    with iers.conf.set_temp("auto_download", False):
        itrs = teme.transform_to(ITRS(obstime=when))
        topo = ITRS(itrs.cartesian.without_differentials() - loc.get_itrs(when).cartesian, obstime=when, location=loc)
        return topo.transform_to(AltAz(obstime=when, location=loc))


def _differences(g, altaz):
    daz = (g.azimuth_deg - altaz.az.deg + 180.0) % 360.0 - 180.0
    cross = np.abs(daz * np.cos(np.radians(altaz.alt.deg)))  # the azimuth error as an angle on the sky
    return max(np.abs(g.elevation_deg - altaz.alt.deg).max(), cross.max()), np.abs(g.range_km - altaz.distance.km).max()


def test_the_pass_agrees_with_sgp4_and_astropy_within_a_hundredth_of_a_degree_and_100_m(tle):
    g = pass_geometry(tle, SITE, START, END, step_s=10.0)
    above = g.elevation_deg > 0
    assert above.sum() > 20 and g.elevation_deg.max() > 20  # a real pass, not a graze
    angle, distance = _differences(g, astropy_altaz(tle, g.times_utc))
    assert angle < 0.01 and distance < 0.1, (angle, distance)
    # the control: the same computation one second late misses by kilometres (7.7 km/s)
    late_angle, late_distance = _differences(g, astropy_altaz(tle, g.times_utc, shift_s=1.0))
    assert late_angle > 0.05 or late_distance > 1.0
    # a daytime pass of a sunlit satellite
    assert np.all(g.sunlit[above]) and set(np.array(g.sky)[above]) == {"day"}
    assert np.all(g.sun_elevation_deg[above] > 10)


def test_the_phase_angle_agrees_with_the_directions_seen_from_the_site(tle):
    """Sun - satellite - observer from the GCRS vectors, against the same angle from the topocentric azimuths and
    elevations of the satellite (astropy) and the sun: the sun is so far that its direction from the satellite is
    its direction from the site (0.0002 deg apart)."""
    g = pass_geometry(tle, SITE, START, END, step_s=30.0)
    altaz = astropy_altaz(tle, g.times_utc)
    sat = _enu(altaz.az.deg, altaz.alt.deg)
    sun = _enu(g.sun_azimuth_deg, g.sun_elevation_deg)
    expected = np.degrees(np.arccos(np.clip(np.sum(-sat * sun, axis=0), -1, 1)))
    assert np.abs(g.phase_angle_deg - expected).max() < 0.01
    assert np.abs(g.phase_angle_deg - (180.0 - expected)).max() > 1.0  # the control: the supplement is far off


def test_each_faces_angles_follow_its_orientation(tle):
    g = pass_geometry(tle, SITE, START, END, step_s=30.0,
                      faces=[Face("panel", 30.0, "sun"), Face("earth", 10.0, "nadir", (0, 0, 1)),
                             Face("zenith", 10.0, "nadir", (0, 0, -1)), Face("fixed", 2.0, "inertial", (0, 0, 1))])
    above = g.elevation_deg > 0
    panel, earth, zenith, fixed = range(4)
    # a sun-tracking panel: normal incidence, and its reflection angle is the phase angle
    assert np.allclose(g.theta_i_deg[:, panel], 0.0, atol=1e-6)
    assert np.allclose(g.theta_r_deg[:, panel], g.phase_angle_deg, atol=1e-6)
    # the Earth-facing face sees the site (nadir angle below 90 deg while it is above the horizon); the zenith face
    # does not, and their angles are supplementary
    assert np.all(g.theta_r_deg[above, earth] < 90) and np.all(g.theta_r_deg[above, zenith] > 90)
    assert np.allclose(g.theta_r_deg[:, earth] + g.theta_r_deg[:, zenith], 180.0, atol=1e-6)
    assert np.allclose(g.theta_i_deg[:, earth] + g.theta_i_deg[:, zenith], 180.0, atol=1e-6)
    # the nadir angle at the satellite follows from the elevation and range (law of sines in the Earth-centre -
    # satellite - site triangle): sin(nadir) = R_site cos(el) / r_sat, with the elevation measured from the geodetic
    # vertical, 0.19 deg from the geocentric one at 43 deg latitude (the tolerance)
    r_sat = np.linalg.norm(g.position_km, axis=0)
    r_site = np.linalg.norm(g.position_km + g.range_km * g.to_observer_unit, axis=0)
    nadir = np.degrees(np.arcsin(r_site * np.cos(np.radians(g.elevation_deg)) / r_sat))
    assert np.abs(g.theta_r_deg[:, earth] - nadir).max() < 0.2
    assert np.abs(g.theta_r_deg[:, zenith] - nadir).min() > 10  # the control
    # an inertial face keeps its normal: theta_i follows only the sun's slow motion over nine minutes
    assert np.ptp(g.theta_i_deg[:, fixed]) < 0.01
    assert np.all((g.dphi_deg > -180) & (g.dphi_deg <= 180))
    rows = g.to_json()["times"]
    assert set(rows[0]["faces"]) == {"panel", "earth", "zenith", "fixed"} and rows[0]["sky"] == "day"


def test_a_damaged_or_ambiguous_tle_is_one_line(tmp_path, tle):
    bad = tmp_path / "bad.tle"
    bad.write_text(f"ISS\n{tle.line1[:-1]}7\n{tle.line2}\n")
    with pytest.raises(SpacepolError, match=r"line 2.*checksum"):
        read_tle(bad)
    two = tmp_path / "two.tle"
    two.write_text(f"ISS\n{tle.line1}\n{tle.line2}\nISS COPY\n{tle.line1}\n{tle.line2}\n")
    with pytest.raises(SpacepolError, match="holds 2 satellites"):
        read_tle(two)
    assert read_tle(two, "iss copy").name == "ISS COPY" and read_tle(two, "25544").name == "ISS"
    with pytest.raises(SpacepolError, match="file not found"):
        read_tle(tmp_path / "none.tle")
    with pytest.raises(SpacepolError, match="no satellite 'HST'"):
        read_tle(two, "HST")
    with pytest.raises(SpacepolError, match="days from the window"):
        pass_geometry(tle, SITE, "2015-01-21T00:32:00Z", "2015-01-21T00:41:00Z")
    with pytest.raises(SpacepolError, match="not after"):
        pass_geometry(tle, SITE, END, START)
