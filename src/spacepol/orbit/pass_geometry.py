"""The geometry of a pass: per time step the satellite's direction (azimuth east of north, elevation) and range
from the site, the sun's elevation, whether the satellite is sunlit and what the sky is (day, twilight, night), the
phase angle (sun - satellite - observer), and for each face of the target the incidence angle theta_i, reflection
angle theta_r and azimuth difference dphi in the face's own frame (DESIGN.md's convention: the source at azimuth 0
about the normal, the viewer at -dphi, dphi in (-180, 180]; 180 deg is the specular plane's forward side).

The satellite: SGP4 on its TLE and skyfield's TEME -> ITRS -> site transformations (no atmospheric refraction;
polar motion left out: < 0.5 arcsec at the site). The sun: astropy (``skylight.sun``). Earth's shadow: a cylinder
of the Earth's equatorial radius along the sun direction (the umbra's cone and the penumbra change the entry and
exit of a low-orbit satellite by a few seconds, about one time step).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from datetime import datetime, timedelta, timezone

import numpy as np

from ..errors import ParameterError
from ..skylight.sun import parse_time, sun_track
from .tle import TLE

EARTH_RADIUS_KM = 6378.137  # WGS84 equatorial radius: the shadow cylinder's
MAX_STEPS = 100_000
MAX_DAYS_FROM_EPOCH = 30.0  # SGP4's error grows by about 1-3 km a day from the epoch of a low orbit's elements
# the sun's elevation (deg) at which each part of the sky's day ends: sunrise/sunset (the upper limb with
# standard refraction), civil, nautical and astronomical twilight
SKY_STATES = ((-0.833, "day"), (-6.0, "civil twilight"), (-12.0, "nautical twilight"), (-18.0, "astronomical twilight"))
ORIENTATIONS = ("nadir", "sun", "inertial")


@dataclass(frozen=True)
class Face:
    """A flat face of the target: ``area_m2`` and how its outward ``normal`` points. ``orientation``: ``nadir`` (a
    nadir-pointing body: ``normal`` in the orbit frame, x along the velocity, z towards the Earth's centre, y
    completing it), ``sun`` (a panel that tracks the sun: its normal is the sun's direction, ``normal`` unused),
    ``inertial`` (``normal`` fixed in the celestial frame GCRS). ``material``: None for the observed run's material
    (its posterior draws), else fixed parameters {"model": spec, name: value, ...} of a model of the library."""

    name: str
    area_m2: float
    orientation: str = "nadir"
    normal: tuple[float, float, float] = (0.0, 0.0, 1.0)
    material: dict | None = None

    def __post_init__(self):
        if self.orientation not in ORIENTATIONS:
            raise ParameterError(f"face '{self.name}': orientation '{self.orientation}' unknown ({', '.join(ORIENTATIONS)})")
        if not (np.isfinite(self.area_m2) and self.area_m2 > 0):
            raise ParameterError(f"face '{self.name}': area_m2 {self.area_m2:g} must be a finite number > 0")
        norm = float(np.linalg.norm(self.normal))
        if len(self.normal) != 3 or not np.isfinite(norm) or norm == 0:
            raise ParameterError(f"face '{self.name}': normal {tuple(self.normal)} must be three finite numbers, not all 0")
        if self.material is not None and not isinstance(self.material.get("model"), str):
            raise ParameterError(f"face '{self.name}': material needs model = \"...\" (a model of the library) and its parameters")

    def normals(self, position_km: np.ndarray, velocity_km_s: np.ndarray, sun_unit: np.ndarray) -> np.ndarray:
        """(3, N) unit outward normals in GCRS at each time (positions, velocities and sun directions (3, N))."""
        n = np.asarray(self.normal, float) / np.linalg.norm(self.normal)
        if self.orientation == "sun":
            return sun_unit
        if self.orientation == "inertial":
            return np.repeat(n[:, None], position_km.shape[1], axis=1)
        x, y, z = orbit_axes(position_km, velocity_km_s)
        out = n[0] * x + n[1] * y + n[2] * z
        return out / np.linalg.norm(out, axis=0)


def orbit_axes(position_km: np.ndarray, velocity_km_s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The orbit frame's unit axes in GCRS, each (3, N): x along the velocity (exactly so on a circular orbit), y
    across the orbit (z x v), z towards the Earth's centre."""
    z = -position_km / np.linalg.norm(position_km, axis=0)
    y = np.cross(z.T, velocity_km_s.T).T
    y /= np.linalg.norm(y, axis=0)
    return np.cross(y.T, z.T).T, y, z


@dataclass
class PassGeometry:
    """The pass over a site at N times: ``times_utc`` (aware datetimes), the satellite's ``azimuth_deg`` (east of
    north), ``elevation_deg`` and ``range_km``, the sun's ``sun_elevation_deg`` and ``sun_azimuth_deg``, ``sunlit``
    (outside Earth's shadow), ``sky`` (day, civil/nautical/astronomical twilight, night), ``phase_angle_deg``
    (sun - satellite - observer; 0 = full phase, the sun behind the observer), and per face (N, faces) arrays
    ``theta_i_deg``, ``theta_r_deg``, ``dphi_deg`` with ``lit`` and ``seen`` (the face turned to the sun, to the
    observer). Vectors in GCRS (km, km/s, unit): ``position_km``, ``velocity_km_s``, ``sun_unit``, ``to_observer_unit``
    (3, N)."""

    satellite: str
    site: tuple[float, float, float]
    times_utc: list[datetime]
    azimuth_deg: np.ndarray
    elevation_deg: np.ndarray
    range_km: np.ndarray
    sun_azimuth_deg: np.ndarray
    sun_elevation_deg: np.ndarray
    sunlit: np.ndarray
    phase_angle_deg: np.ndarray
    position_km: np.ndarray
    velocity_km_s: np.ndarray
    sun_unit: np.ndarray
    to_observer_unit: np.ndarray
    faces: list[Face] = field(default_factory=list)
    theta_i_deg: np.ndarray | None = None
    theta_r_deg: np.ndarray | None = None
    dphi_deg: np.ndarray | None = None

    def normals(self, k: int) -> np.ndarray:
        """(3, N) unit outward normals of face ``k`` in GCRS."""
        return self.faces[k].normals(self.position_km, self.velocity_km_s, self.sun_unit)

    @property
    def sky(self) -> list[str]:
        """The sky at each time: day, civil, nautical or astronomical twilight, or night (from the sun's elevation)."""
        return [next((name for limit, name in SKY_STATES if e > limit), "night") for e in self.sun_elevation_deg]

    @property
    def lit(self) -> np.ndarray:
        """(N, faces): the face turns towards the sun and the satellite is sunlit."""
        return (self.theta_i_deg < 90.0) & self.sunlit[:, None]

    @property
    def seen(self) -> np.ndarray:
        """(N, faces): the face turns towards the observer and the satellite is above the horizon."""
        return (self.theta_r_deg < 90.0) & (self.elevation_deg > 0.0)[:, None]

    @property
    def visible(self) -> np.ndarray:
        """(N,): above the horizon and sunlit."""
        return (self.elevation_deg > 0.0) & self.sunlit

    def to_json(self) -> dict:
        """The pass as JSON: site, satellite and one record per time."""
        rows = []
        for j, t in enumerate(self.times_utc):
            row = {"time_utc": t.isoformat().replace("+00:00", "Z"), "azimuth_deg": float(self.azimuth_deg[j]),
                   "elevation_deg": float(self.elevation_deg[j]), "range_km": float(self.range_km[j]),
                   "sun_elevation_deg": float(self.sun_elevation_deg[j]), "sun_azimuth_deg": float(self.sun_azimuth_deg[j]),
                   "sunlit": bool(self.sunlit[j]), "sky": self.sky[j], "phase_angle_deg": float(self.phase_angle_deg[j])}
            if self.faces:
                row["faces"] = {f.name: {"theta_i_deg": float(self.theta_i_deg[j, k]), "theta_r_deg": float(self.theta_r_deg[j, k]),
                                         "dphi_deg": float(self.dphi_deg[j, k]), "lit": bool(self.lit[j, k]),
                                         "seen": bool(self.seen[j, k])} for k, f in enumerate(self.faces)}
            rows.append(row)
        lat, lon, height = self.site
        return {"satellite": self.satellite, "site": {"lat_deg": lat, "lon_deg": lon, "height_m": height}, "times": rows}


def _angle_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle between unit vectors (3, N), robust near 0 and 180 deg."""
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a.T, b.T), axis=-1), np.sum(a * b, axis=0)))


def face_angles(normal: np.ndarray, to_sun: np.ndarray, to_observer: np.ndarray):
    """(theta_i, theta_r, dphi) in degrees for unit normals and unit directions to the source and to the viewer
    (each (3, N)), in DESIGN.md's convention: the source at azimuth 0 about the normal, the viewer at azimuth -dphi,
    dphi in (-180, 180] (180: the specular plane's forward side). Its sign decides the sign of S2 in the face's
    basis, so it is kept."""
    theta_i, theta_r = _angle_deg(normal, to_sun), _angle_deg(normal, to_observer)
    ti = to_sun - np.sum(to_sun * normal, axis=0) * normal
    tr = to_observer - np.sum(to_observer * normal, axis=0) * normal
    norm_i, norm_r = np.linalg.norm(ti, axis=0), np.linalg.norm(tr, axis=0)
    # at normal incidence the source's azimuth is undefined: any x axis will do (the model is symmetric about it)
    x = np.where(norm_i > 1e-12, ti / np.where(norm_i > 1e-12, norm_i, 1.0), _any_perpendicular(normal))
    y = np.cross(normal.T, x.T).T
    phi_r = np.degrees(np.arctan2(np.sum(tr * y, axis=0), np.sum(tr * x, axis=0)))
    dphi = np.where(norm_r > 1e-12, -phi_r, 180.0)  # at normal view: the specular plane, by convention
    return theta_i, theta_r, np.where(dphi <= -180.0, dphi + 360.0, dphi)


def _any_perpendicular(normal: np.ndarray) -> np.ndarray:
    """(3, N) unit vectors perpendicular to the unit ``normal`` (3, N)."""
    helper = np.where(np.abs(normal[2]) < 0.9, np.array([0.0, 0.0, 1.0])[:, None], np.array([1.0, 0.0, 0.0])[:, None])
    out = np.cross(normal.T, helper.T).T
    return out / np.linalg.norm(out, axis=0)


def time_steps(start, end, step_s: float) -> list[datetime]:
    """UTC times from ``start`` to ``end`` (ISO 8601 with offset, or aware datetimes) every ``step_s`` seconds."""
    start = parse_time(start) if isinstance(start, str) else start.astimezone(timezone.utc)
    end = parse_time(end) if isinstance(end, str) else end.astimezone(timezone.utc)
    if not (np.isfinite(step_s) and step_s > 0):
        raise ParameterError(f"--step {step_s:g}: the time step must be a finite number of seconds > 0")
    if end <= start:
        raise ParameterError(f"--end {end.isoformat()} is not after --start {start.isoformat()}")
    count = int(np.floor((end - start).total_seconds() / step_s)) + 1
    if count > MAX_STEPS:
        raise ParameterError(f"--start/--end/--step: {count} time steps, more than {MAX_STEPS}; take a longer step")
    return [start + timedelta(seconds=k * step_s) for k in range(count)]


def pass_geometry(tle: TLE, site: tuple, start, end, step_s: float = 10.0, faces=()) -> PassGeometry:
    """The pass of the satellite of ``tle`` over ``site`` (lat_deg, lon_deg[, height_m]) from ``start`` to ``end``
    every ``step_s`` seconds, with each face's angles. One line for a site off the globe, a window far from the
    elements' epoch, or a satellite SGP4 cannot propagate (decayed)."""
    return pass_geometry_at(tle, site, time_steps(start, end, step_s), faces)


def pass_geometry_at(tle: TLE, site: tuple, times: list[datetime], faces=()) -> PassGeometry:
    """``pass_geometry`` at the given aware ``times`` (e.g. a measured light curve's)."""
    from skyfield.api import EarthSatellite, load, wgs84

    lat, lon, height = (tuple(float(v) for v in site) + (0.0,))[:3]
    if not -90.0 <= lat <= 90.0 or not -180.0 <= lon <= 360.0 or not np.isfinite(height):
        raise ParameterError(f"--site {lat:g},{lon:g},{height:g}: latitude in [-90, 90], longitude in [-180, 360] deg, "
                             "height in metres")
    ts = load.timescale(builtin=True)  # leap seconds and Delta T bundled with skyfield: no download
    satellite = EarthSatellite(tle.line1, tle.line2, tle.name, ts)
    t = ts.from_datetimes(times)
    days = np.abs(t.tt - satellite.epoch.tt)
    if days.max() > MAX_DAYS_FROM_EPOCH:
        raise ParameterError(f"{tle.source or tle.name}: the elements' epoch {satellite.epoch.utc_iso()} is "
                             f"{days.max():.0f} days from the window; SGP4 is meaningful within about "
                             f"{MAX_DAYS_FROM_EPOCH:.0f} days of it (take newer elements)")
    place = wgs84.latlon(lat, lon, elevation_m=height)
    geocentric = satellite.at(t)
    position, velocity = geocentric.position.km, geocentric.velocity.km_per_s
    if not np.all(np.isfinite(position)):
        raise ParameterError(f"{tle.source or tle.name}: SGP4 cannot propagate {tle.name} over this window "
                             f"({geocentric.message if hasattr(geocentric, 'message') else 'no position'})")
    elevation, azimuth, distance = (satellite - place).at(t).altaz()
    observer = place.at(t).position.km
    sun_zenith, sun_azimuth, sun_unit = sun_track(lat, lon, times, height)
    to_observer = observer - position
    to_observer /= np.linalg.norm(to_observer, axis=0)
    along = np.sum(position * sun_unit, axis=0)  # the satellite's distance along the sun direction
    off_axis = np.linalg.norm(position - along * sun_unit, axis=0)
    sunlit = (along > 0) | (off_axis > EARTH_RADIUS_KM)
    out = PassGeometry(tle.name, (lat, lon, height), times, azimuth.degrees % 360.0, elevation.degrees, distance.km,
                       sun_azimuth, 90.0 - sun_zenith, sunlit, _angle_deg(sun_unit, to_observer), position, velocity,
                       sun_unit, to_observer, list(faces))
    if faces:
        angles = [face_angles(out.normals(k), sun_unit, to_observer) for k in range(len(faces))]
        out.theta_i_deg, out.theta_r_deg, out.dphi_deg = (np.stack([a[i] for a in angles], axis=1) for i in range(3))
    return out
