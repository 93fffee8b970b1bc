"""Single-scattering Rayleigh sky (paper eqs 26-30, corrected).

DOP = P_max sin^2(gamma) / (1 + cos^2(gamma)) (eq 28), gamma the scattering angle between the
sun and the viewing direction. The E-vector is perpendicular to the scattering plane (sun,
observer, view): e = s x v / |s x v|, and the angle of polarization is that of e from the local
meridian (``directions.angle_of_polarization``). P_max = 1 is the ideal; a clear sky peaks near
0.7-0.8 because of multiple scattering, aerosols and ground reflection, which also create neutral
points that this model lacks (see ``neutral_points``).

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from .directions import angle_of_polarization, unit_vector


@dataclass(frozen=True)
class RayleighSky:
    """Single-scattering Rayleigh skylight polarization, scaled to a maximum DOP ``p_max``."""
    p_max: float = 1.0
    name = "rayleigh"

    def __post_init__(self):
        if not 0.0 <= self.p_max <= 1.0:
            raise ParameterError(f"P_max = {self.p_max}: a degree of polarization lies in [0, 1]")

    def scattering_cosine(self, zenith_deg, azimuth_deg, sun) -> np.ndarray:
        """Cosine of the scattering angle between the sun and each direction."""
        v = unit_vector(zenith_deg, azimuth_deg)
        s = unit_vector(sun[0], sun[1])
        return np.clip(np.sum(v * s, axis=-1), -1.0, 1.0)

    def dop(self, zenith_deg, azimuth_deg, sun) -> np.ndarray:
        """``sun`` = (zenith_deg, azimuth_deg) of the sun."""
        c2 = self.scattering_cosine(zenith_deg, azimuth_deg, sun) ** 2
        return self.p_max * (1.0 - c2) / (1.0 + c2)

    def e_vector(self, zenith_deg, azimuth_deg, sun) -> np.ndarray:
        """The E-vector of single Rayleigh scattering (perpendicular to the scattering plane) as unit vectors; NaN at
        the sun and anti-sun."""
        v = unit_vector(zenith_deg, azimuth_deg)
        s = unit_vector(sun[0], sun[1])
        e = np.cross(np.broadcast_to(s, v.shape), v)
        norm = np.linalg.norm(e, axis=-1, keepdims=True)
        return np.where(norm > 1e-12, e / np.where(norm > 0, norm, 1.0), np.nan)  # undefined at sun / anti-sun

    def aop(self, zenith_deg, azimuth_deg, sun) -> np.ndarray:
        """Angle of polarization (deg) from the local meridian (``directions.angle_of_polarization``)."""
        return angle_of_polarization(self.e_vector(zenith_deg, azimuth_deg, sun), zenith_deg, azimuth_deg)


def paper_scattering_cosine(altitude_deg, azimuth_deg, sun_altitude_deg, sun_azimuth_deg) -> np.ndarray:
    """Eq 27 as printed; theta there is the altitude."""
    h, hs = np.radians(altitude_deg), np.radians(sun_altitude_deg)
    return np.sin(h) * np.sin(hs) + np.cos(h) * np.cos(hs) * np.cos(np.radians(azimuth_deg - sun_azimuth_deg))


def paper_aop(theta_deg, azimuth_deg, sun_theta_deg, sun_azimuth_deg) -> np.ndarray:
    """Eq 30 as printed, chi = arctan(...), folded to (-90, 90]; right only when theta is the zenith angle."""
    t, ts = np.radians(theta_deg), np.radians(sun_theta_deg)
    d = np.radians(azimuth_deg - sun_azimuth_deg)
    num = np.sin(t) * np.cos(ts) - np.cos(t) * np.sin(ts) * np.cos(d)
    den = np.sin(d) * np.sin(ts)
    return np.degrees(np.arctan(num / den))
