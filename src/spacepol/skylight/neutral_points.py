"""A sky with neutral points: Berry, Dennis & Lee (2004, New J. Phys. 6, 162).

Single scattering has two singular points of index +1, the sun S and the anti-sun A. Multiple
scattering splits each into two points of index +1/2 with zero polarization, on the sun's
vertical: Babinet (above the sun) and Brewster (below), Arago (above the anti-sun) and a
fourth below it. In the stereographic plane zeta = tan(theta/2) exp(i(90 deg - phi)) (x east,
y north) the Rayleigh pattern is

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from .directions import angles, fold_axial, unit_vector


def _rotate_towards_zenith(v, delta_deg):
    """Rotate directions v by delta along their vertical (towards the zenith for delta > 0)."""
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(v, z)
    n = np.linalg.norm(axis)
    axis = axis / n if n > 1e-12 else np.array([1.0, 0.0, 0.0])
    d = np.radians(delta_deg)
    return v * np.cos(d) + np.cross(axis, v) * np.sin(d) + axis * np.dot(axis, v) * (1 - np.cos(d))


def _homogeneous(v):
    zen, az = angles(v)
    t, p = np.radians(zen) / 2, np.radians(90.0 - az)
    return np.sin(t) * np.exp(1j * p), np.cos(t)


def stereographic_zeta(zenith_deg, azimuth_deg):
    """The stereographic coordinate of a sky direction as a complex number (Berry, Dennis and Lee's zeta)."""
    return np.tan(np.radians(zenith_deg) / 2) * np.exp(1j * np.radians(90.0 - np.asarray(azimuth_deg, float)))


@dataclass(frozen=True)
class BerryDennisLeeSky:
    """Skylight polarization with the four neutral points (Berry, Dennis & Lee 2004): maximum DOP ``p_max``, each
    neutral point ``delta_deg`` from the sun or anti-sun."""
    p_max: float = 0.8
    delta_deg: float = 20.0  # angular distance of each neutral point from the sun (anti-sun)
    name = "berry-dennis-lee"

    def __post_init__(self):
        if not 0.0 <= self.p_max <= 1.0:
            raise ParameterError(f"P_max = {self.p_max}: a degree of polarization lies in [0, 1]")
        if not 0.0 <= self.delta_deg < 90.0:
            raise ParameterError(f"delta = {self.delta_deg} deg: the neutral points' distance must be in [0, 90)")

    def neutral_points(self, sun) -> dict[str, tuple[float, float]]:
        """(zenith, azimuth) of Babinet, Brewster, Arago and the fourth point."""
        s = unit_vector(*sun)
        a = -s
        pts = {"babinet": _rotate_towards_zenith(s, self.delta_deg), "brewster": _rotate_towards_zenith(s, -self.delta_deg),
               "arago": _rotate_towards_zenith(a, self.delta_deg), "fourth": _rotate_towards_zenith(a, -self.delta_deg)}
        return {k: tuple(float(x) for x in angles(v)) for k, v in pts.items()}

    def w(self, zenith_deg, azimuth_deg, sun) -> np.ndarray:
        """Berry, Dennis and Lee's complex polarization field w at the directions: |w| sets the DOP, arg(w)/2 the angle
        of polarization."""
        zeta = stereographic_zeta(zenith_deg, azimuth_deg)
        s = unit_vector(*sun)
        points = [unit_vector(*p) for p in self.neutral_points(sun).values()]
        w = -4.0 / (1.0 + np.abs(zeta) ** 2) ** 2
        for p in points:
            a, b = _homogeneous(p)
            w = w * (zeta * b - a)
        # phase of the unsplit pattern, so that delta = 0 is exactly Rayleigh: (zeta_S - zeta_A)^-2 direction
        (a_s, b_s), (a_a, b_a) = _homogeneous(s), _homogeneous(-s)
        ref = a_s * b_a - a_a * b_s
        return w * np.conj(ref) ** 2 / np.abs(ref) ** 2

    def dop(self, zenith_deg, azimuth_deg, sun) -> np.ndarray:
        """The sky's DOP: P_max |w| / (2 - |w|), zero at the four neutral points."""
        m = np.minimum(np.abs(self.w(zenith_deg, azimuth_deg, sun)), 1.0)
        return self.p_max * m / (2.0 - m)

    def aop(self, zenith_deg, azimuth_deg, sun) -> np.ndarray:
        """E-vector direction arg(w)/2 in the plane, measured from the local meridian (towards the
        zenith: -zeta/|zeta| in the plane). The plane (x east, y north) shows the sky from above,
        so the sign follows the vector definition in ``directions`` (a test checks delta = 0)."""
        zeta = stereographic_zeta(zenith_deg, np.asarray(azimuth_deg, float))
        direction = np.angle(self.w(zenith_deg, azimuth_deg, sun)) / 2
        up = np.angle(-zeta)
        return fold_axial(np.degrees(direction - up))
