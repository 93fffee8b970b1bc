"""A satellite's attitude as offsets from its nominal orientation: yaw, pitch and roll (degrees), the z-y-x
sequence about the orbit frame's axes (x along the velocity, z towards the Earth's centre), R = Rz Ry Rx, turning the
faces that turn with the body (``orientation = "nadir"``).

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..errors import ParameterError

ANGLES = ("yaw_deg", "pitch_deg", "roll_deg")


@dataclass(frozen=True)
class Attitude:
    """Offsets from the nominal orientation in degrees (``yaw_deg`` about the nadir axis z, ``pitch_deg`` about the
    cross-track axis y, ``roll_deg`` about the velocity axis x); all 0 is the nominal attitude."""

    yaw_deg: float = 0.0
    pitch_deg: float = 0.0
    roll_deg: float = 0.0

    def __post_init__(self):
        for name in ANGLES:
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and not isinstance(value, bool) and np.isfinite(value)):
                raise ParameterError(f"attitude {name} = {value!r}: need a finite number of degrees")

    def rotation(self) -> np.ndarray:
        """(3, 3) R = Rz(yaw) Ry(pitch) Rx(roll): a body-frame vector's orbit-frame components are R @ v."""
        return rotations(np.array([self.yaw_deg]), np.array([self.pitch_deg]), np.array([self.roll_deg]))[0]

    def to_json(self) -> dict:
        """{yaw_deg, pitch_deg, roll_deg}."""
        return {name: float(getattr(self, name)) for name in ANGLES}


def rotations(yaw_deg, pitch_deg, roll_deg) -> np.ndarray:
    """(S, 3, 3) the rotations Rz(yaw) Ry(pitch) Rx(roll) for S sets of offsets (degrees, arrays of length S)."""
    y, p, r = (np.radians(np.atleast_1d(np.asarray(a, float))) for a in (yaw_deg, pitch_deg, roll_deg))
    cy, sy, cp, sp, cr, sr = np.cos(y), np.sin(y), np.cos(p), np.sin(p), np.cos(r), np.sin(r)
    return np.stack([
        np.stack([cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr], axis=-1),
        np.stack([sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr], axis=-1),
        np.stack([-sp, cp * sr, cp * cr], axis=-1),
    ], axis=-2)


def turned(faces, attitude: Attitude) -> list:
    """The faces under ``attitude``: each nadir face's body-frame normal turned by its rotation (the others as they
    are)."""
    rotation = attitude.rotation()
    return [replace(f, normal=tuple(float(v) for v in rotation @ np.asarray(f.normal, float)))
            if f.orientation == "nadir" else f for f in faces]


def attitude_from_table(table, source: str) -> Attitude:
    """An ``attitude = {yaw_deg, pitch_deg, roll_deg}`` table of a target file (a missing angle is 0); an unknown key
    or a value that is not a number is one line naming ``source``."""
    if not isinstance(table, dict):
        raise ParameterError(f"{source}: attitude must be a table {{yaw_deg = ..., pitch_deg = ..., roll_deg = ...}}")
    unknown = sorted(set(table) - set(ANGLES))
    if unknown:
        raise ParameterError(f"{source}: attitude has no key {', '.join(unknown)} (known: {', '.join(ANGLES)})")
    try:
        return Attitude(**{name: table.get(name, 0.0) for name in ANGLES})
    except ParameterError as exc:
        raise ParameterError(f"{source}: {exc}") from None
