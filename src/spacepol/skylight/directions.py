"""Directions on the sky as unit vectors in the local frame x = east, y = north, z = up.

(zenith angle theta, azimuth phi east of north) -> (sin theta sin phi, sin theta cos phi, cos theta).
The local reference for angles of polarization at a direction v: ``up`` (the tangent towards the
zenith, along the meridian) and ``east`` (towards increasing azimuth).
"""

from __future__ import annotations

import numpy as np


def unit_vector(zenith_deg, azimuth_deg) -> np.ndarray:
    """Unit vectors (x east, y north, z up) of directions at zenith and azimuth (deg, east of north)."""
    t, p = np.radians(zenith_deg), np.radians(azimuth_deg)
    return np.stack(np.broadcast_arrays(np.sin(t) * np.sin(p), np.sin(t) * np.cos(p), np.cos(t)), axis=-1)


def angles(v) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors -> (zenith angle, azimuth east of north) in degrees."""
    v = np.asarray(v, float)
    zen = np.degrees(np.arccos(np.clip(v[..., 2], -1.0, 1.0)))
    az = np.degrees(np.arctan2(v[..., 0], v[..., 1])) % 360.0
    return zen, az


def local_frame(zenith_deg, azimuth_deg) -> tuple[np.ndarray, np.ndarray]:
    """(up, east) tangent unit vectors at each direction: up = -d v / d theta, east = d v / d phi / sin theta.
    At the zenith the limit along the given azimuth is used."""
    t, p = np.radians(zenith_deg), np.radians(azimuth_deg)
    up = np.stack(np.broadcast_arrays(-np.cos(t) * np.sin(p), -np.cos(t) * np.cos(p), np.sin(t)), axis=-1)
    east = np.stack(np.broadcast_arrays(np.cos(p), -np.sin(p), 0.0 * t), axis=-1)
    return up, east


def angle_of_polarization(e, zenith_deg, azimuth_deg) -> np.ndarray:
    """Angle (deg, in (-90, 90]) of the E-vector ``e`` from the local meridian (up), positive towards
    increasing azimuth (east)."""
    up, east = local_frame(zenith_deg, azimuth_deg)
    chi = np.degrees(np.arctan2(np.sum(e * east, axis=-1), np.sum(e * up, axis=-1)))
    return fold_axial(chi)


def fold_axial(angle_deg) -> np.ndarray:
    """An axis angle (defined modulo 180 deg) into (-90, 90]."""
    a = (np.asarray(angle_deg, float) + 90.0) % 180.0 - 90.0
    return np.where(a == -90.0, 90.0, a)
