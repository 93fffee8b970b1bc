"""Maps of the sky hemisphere onto a plane, with inverses and Tissot distortion.

Every projection here is azimuthal: a direction (zenith angle theta, azimuth phi east of north)
goes to radius r(theta) at angle phi, x = r sin(phi) (east), y = r cos(phi) (north), the
zenith at the centre (the sky seen from above, as in the paper's figures). Tissot's indicatrix
follows from r alone: the scale along the meridian h = dr/dtheta and along the parallel
k = r / sin(theta); the areal scale is h k and the maximum angular distortion
omega = 2 arcsin(|h - k| / (h + k)).

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import UnknownNameError


@dataclass(frozen=True)
class Projection:
    """A map of the sky hemisphere: radius on the map from the zenith angle and back, and its radial scale."""
    name: str
    label: str

    def radius(self, theta):
        """Radius on the map of a zenith angle (radians)."""
        raise NotImplementedError

    def zenith_angle(self, r):
        """Zenith angle (radians) of a radius on the map."""
        raise NotImplementedError

    def radial_scale(self, theta):
        """h = dr/dtheta."""
        raise NotImplementedError

    def forward(self, zenith_deg, azimuth_deg) -> tuple[np.ndarray, np.ndarray]:
        """Map coordinates (x east, y north) of directions at zenith and azimuth (deg)."""
        r = self.radius(np.radians(zenith_deg))
        phi = np.radians(azimuth_deg)
        return r * np.sin(phi), r * np.cos(phi)

    def inverse(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """(zenith, azimuth) in degrees; azimuth 0 at the centre."""
        r = np.hypot(x, y)
        return np.degrees(self.zenith_angle(r)), np.degrees(np.arctan2(x, y)) % 360.0

    def horizon_radius(self) -> float:
        """The map radius of the horizon."""
        return float(self.radius(np.pi / 2))

    def tissot(self, zenith_deg) -> dict[str, np.ndarray]:
        """Scale factors h (meridian), k (parallel), areal scale h k, angular distortion omega (deg)."""
        theta = np.radians(np.asarray(zenith_deg, float))
        h = self.radial_scale(theta)
        with np.errstate(invalid="ignore", divide="ignore"):
            k = np.where(theta > 1e-12, self.radius(theta) / np.sin(np.where(theta > 1e-12, theta, 1.0)), h)
        omega = np.degrees(2 * np.arcsin(np.abs(h - k) / (h + k)))
        return {"h": h, "k": k, "areal_scale": h * k, "angular_distortion_deg": omega}


class Stereographic(Projection):
    """Stereographic projection r = 2 tan(theta / 2): conformal (the paper's "complex spherical" plane)."""

    def radius(self, theta):
        return 2 * np.tan(np.asarray(theta) / 2)

    def zenith_angle(self, r):
        return 2 * np.arctan(np.asarray(r) / 2)

    def radial_scale(self, theta):
        return 1 / np.cos(np.asarray(theta) / 2) ** 2


class Orthographic(Projection):
    """Orthographic projection r = sin(theta): the sky as seen from far above."""

    def radius(self, theta):
        return np.sin(theta)

    def zenith_angle(self, r):
        return np.arcsin(np.clip(r, 0.0, 1.0))

    def radial_scale(self, theta):
        return np.cos(theta)


class LambertEqualArea(Projection):
    """Lambert azimuthal equal-area projection r = 2 sin(theta / 2): areas kept."""

    def radius(self, theta):
        return 2 * np.sin(np.asarray(theta) / 2)

    def zenith_angle(self, r):
        return 2 * np.arcsin(np.clip(np.asarray(r) / 2, 0.0, 1.0))

    def radial_scale(self, theta):
        return np.cos(np.asarray(theta) / 2)


PROJECTIONS = {
    "stereographic": Stereographic("stereographic", "stereographic (paper's complex spherical, eq 33)"),
    "orthographic": Orthographic("orthographic", "orthographic (paper's direct vertical)"),
    "equal-area": LambertEqualArea("equal-area", "Lambert azimuthal equal-area"),
}


def projection(name: str) -> Projection:
    """The projection of this name (stereographic, orthographic, lambert); an unknown name is one line."""
    try:
        return PROJECTIONS[name]
    except KeyError:
        raise UnknownNameError(f"unknown projection '{name}' (choose from {', '.join(PROJECTIONS)})") from None


def cap_fraction(proj: Projection, cap_zenith_deg: float) -> float:
    """Share of the map's hemisphere disc taken by the cap theta <= cap (the true share of solid
    angle is 1 - cos(cap))."""
    return float((proj.radius(np.radians(cap_zenith_deg)) / proj.horizon_radius()) ** 2)
