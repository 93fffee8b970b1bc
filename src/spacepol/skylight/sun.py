"""Where the sun is, from site and time: astropy's ephemeris, no hand-written formulae.

Azimuth is measured in degrees east of north; zenith angle from the local vertical. No
atmospheric refraction is applied (it lifts the sun by < 0.6 deg at the horizon, ~0.03 deg
at 60 deg zenith angle).
"""

from __future__ import annotations

import sys
import warnings
from dataclasses import dataclass
from datetime import datetime, timezone

from ..errors import ParameterError

# Earth-orientation tables run out (UT1-UTC predictions about a year ahead, leap seconds announced
# months ahead).  Beyond them astropy assumes the last values: UT1-UTC stays below 0.9 s by
# definition, i.e. < 0.004 deg of solar hour angle, far below the 0.05 deg the tests ask for.
_DEGRADED_NOTE = ("note: {when} lies outside astropy's bundled Earth-orientation tables; the sun's position "
                  "uses their nearest values (error < 0.01 deg while civil time stays within a second of Earth rotation)")
_warned: set[str] = set()


def _note_once(key: str, text: str) -> None:
    if key not in _warned:
        _warned.add(key)
        print(text, file=sys.stderr)


@dataclass(frozen=True)
class SunPosition:
    """The sun's zenith and azimuth (degrees, azimuth east of north) at a UTC time."""
    zenith_deg: float
    azimuth_deg: float  # east of north
    time_utc: str

    @property
    def altitude_deg(self) -> float:
        """The sun's altitude above the horizon (90 - zenith), degrees."""
        return 90.0 - self.zenith_deg


def parse_time(text: str) -> datetime:
    """ISO 8601 with a UTC offset ('2020-12-16T11:42+08:00' or '...Z'); a naive time is refused."""
    try:
        t = datetime.fromisoformat(text.replace("Z", "+00:00"))
    except ValueError:
        raise ParameterError(f"--time '{text}': not an ISO 8601 time (e.g. 2020-12-16T11:42+08:00)") from None
    if t.tzinfo is None:
        raise ParameterError(f"--time '{text}': give the UTC offset (e.g. +08:00 or Z); local time is ambiguous")
    try:
        utc = t.astimezone(timezone.utc)
    except OverflowError:
        utc = None
    if utc is None or not 1000 <= utc.year <= 3000:
        raise ParameterError(f"--time '{text}': outside the years 1000-3000, where the solar ephemeris and "
                             f"Earth-rotation models are meaningful")
    return utc


def sun_position(lat_deg: float, lon_deg: float, time: str | datetime, height_m: float = 0.0) -> SunPosition:
    """The sun seen from (lat, lon) at ``time`` (ISO 8601 with offset, or an aware datetime)."""
    if not -90.0 <= lat_deg <= 90.0:
        raise ParameterError(f"--lat {lat_deg}: latitude must be within [-90, 90] deg")
    if not -180.0 <= lon_deg <= 360.0:
        raise ParameterError(f"--lon {lon_deg}: longitude must be within [-180, 360] deg")
    utc = parse_time(time) if isinstance(time, str) else time.astimezone(timezone.utc)
    zenith, azimuth, _ = sun_track(lat_deg, lon_deg, [utc], height_m)
    return SunPosition(float(zenith[0]), float(azimuth[0]), utc.isoformat())


def sun_track(lat_deg: float, lon_deg: float, times_utc, height_m: float = 0.0):
    """The sun over many times (aware datetimes) at one site: (zenith_deg (N,), azimuth_deg (N,) east of north, unit
    vectors towards the sun (3, N) in the geocentric celestial frame GCRS); no refraction; offline, any date."""
    import astropy.units as u
    import numpy as np
    from astropy.coordinates import AltAz, EarthLocation, get_sun
    from astropy.time import Time
    from astropy.utils import iers

    utc = [t.astimezone(timezone.utc).replace(tzinfo=None) for t in times_utc]
    site = EarthLocation(lat=lat_deg * u.deg, lon=lon_deg * u.deg, height=height_m * u.m)
    # offline, any date: bundled tables, never an age limit, extrapolate (with a warning) past their end
    with iers.conf.set_temp("auto_download", False), iers.conf.set_temp("auto_max_age", None), \
            iers.conf.set_temp("iers_degraded_accuracy", "warn"), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        when = Time(utc, scale="utc")
        sun = get_sun(when)
        altaz = sun.transform_to(AltAz(obstime=when, location=site))  # pressure 0: no refraction
    if any(("IERS" in str(w.message) or "leap" in str(w.message).lower() or "dubious" in str(w.message).lower())
           for w in caught):
        _note_once("iers", _DEGRADED_NOTE.format(when=utc[0].date().isoformat()))
    xyz = np.atleast_2d(sun.cartesian.xyz.to(u.km).value.T).T
    return (np.atleast_1d(90.0 - altaz.alt.deg), np.atleast_1d(altaz.az.deg % 360.0),
            xyz / np.linalg.norm(xyz, axis=0))
