"""Where the sun is, from site and time: astropy's ephemeris, no hand-written formulae.

Azimuth is measured in degrees east of north; zenith angle from the local vertical. No
atmospheric refraction is applied (it lifts the sun by < 0.6 deg at the horizon, ~0.03 deg
at 60 deg zenith angle).
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import datetime, timezone

from ..errors import ParameterError


@dataclass(frozen=True)
class SunPosition:
    zenith_deg: float
    azimuth_deg: float  # east of north
    time_utc: str

    @property
    def altitude_deg(self) -> float:
        return 90.0 - self.zenith_deg


def parse_time(text: str) -> datetime:
    """ISO 8601 with a UTC offset ('2020-12-16T11:42+08:00' or '...Z'); a naive time is refused."""
    try:
        t = datetime.fromisoformat(text.replace("Z", "+00:00"))
    except ValueError:
        raise ParameterError(f"--time '{text}': not an ISO 8601 time (e.g. 2020-12-16T11:42+08:00)") from None
    if t.tzinfo is None:
        raise ParameterError(f"--time '{text}': give the UTC offset (e.g. +08:00 or Z); local time is ambiguous")
    return t.astimezone(timezone.utc)


def sun_position(lat_deg: float, lon_deg: float, time: str | datetime, height_m: float = 0.0) -> SunPosition:
    """The sun seen from (lat, lon) at ``time`` (ISO 8601 with offset, or an aware datetime)."""
    if not -90.0 <= lat_deg <= 90.0:
        raise ParameterError(f"--lat {lat_deg}: latitude must be within [-90, 90] deg")
    if not -180.0 <= lon_deg <= 360.0:
        raise ParameterError(f"--lon {lon_deg}: longitude must be within [-180, 360] deg")
    import astropy.units as u
    from astropy.coordinates import AltAz, EarthLocation, get_sun
    from astropy.time import Time
    from astropy.utils import iers

    iers.conf.auto_download = False  # offline: astropy's bundled IERS tables (UT1-UTC < 1 s is irrelevant here)
    utc = parse_time(time) if isinstance(time, str) else time.astimezone(timezone.utc)
    when = Time(utc.replace(tzinfo=None), scale="utc")
    site = EarthLocation(lat=lat_deg * u.deg, lon=lon_deg * u.deg, height=height_m * u.m)
    altaz = get_sun(when).transform_to(AltAz(obstime=when, location=site))  # pressure 0: no refraction
    return SunPosition(float(90.0 - altaz.alt.deg), float(altaz.az.deg % 360.0), utc.isoformat())
