"""The forward model of a light-curve inversion: for sets of unknowns (the unknown faces' material parameters and,
where the target file gives none, the attitude offsets) the target's Stokes flux at the site at each time.

The faces turn with the attitude (``orbit.attitude``), each face's angles follow (``pass_geometry.face_angles``), the
material's model gives each lit and seen face's Stokes vector, and the faces' light adds up in the observer's sky
basis as ``target.target_light`` adds it (the same scale E cos(theta_i) A cos(theta_r) / R^2 and rotation).

Each evaluation takes S sets at once: the material's model is evaluated for the S sets, each at its own geometry (one
geometry row per set: S T F evaluations).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from ..orbit.attitude import ANGLES, Attitude, rotations
from ..orbit.pass_geometry import face_angles, orbit_axes
from ..physics.compiled import bucket
from ..physics.geometry import Geometry
from ..priors import Prior, Uniform
from .materials import Material
from .target import by_material, fixed_material, rotation_to_sky, sky_basis, solar_band

ATTITUDE_LIMIT_DEG = 60.0  # the attitude offsets' prior: uniform within this many degrees of the nominal orientation
_VIEW_LIMIT_DEG = 89.9  # a face seen or lit more obliquely sends no light; the model is evaluated at most here


@dataclass
class LightCurveModel:
    """The target of ``geometry`` (a ``PassGeometry`` at the light curve's times, its faces at the nominal
    attitude) with the faces that have no material made of ``material``; ``attitude`` the known offsets, or None
    for offsets to infer. ``names`` and ``priors``: the unknowns, the material's free parameters first."""

    geometry: object
    material: Material
    attitude: Attitude | None = None
    band_um: tuple = (1.5, 1.8)
    names: list[str] = field(init=False)
    priors: list[Prior] = field(init=False)

    def __post_init__(self):
        from ..physics.model import Model

        if not any(f.material is None for f in self.geometry.faces):
            raise ParameterError("target: every face has its own material, so there is no unknown material to infer "
                                 "(leave the material table out of the faces made of it)")
        self.model = Model.from_string(self.material.model)
        free = {k: p for k, p in self.material.priors.items() if not p.is_fixed}
        self._held = {k: float(p.value) for k, p in self.material.priors.items() if p.is_fixed}
        self.names, self.priors = list(free), list(free.values())
        if self.attitude is None:
            self.names += list(ANGLES)
            self.priors += [Uniform(-ATTITUDE_LIMIT_DEG, ATTITUDE_LIMIT_DEG)] * len(ANGLES)
        _, photons = solar_band(*self.band_um)
        self._scale = photons  # photons m^-2 s^-1 per unit of the BRDF-weighted geometry factor
        g = self.geometry
        self._axes = orbit_axes(g.position_km, g.velocity_km_s)
        self._sky_s, _ = sky_basis(g)

    @property
    def ndim(self) -> int:
        """How many unknowns."""
        return len(self.names)

    def log_prior(self, theta: np.ndarray) -> np.ndarray:
        """(S,) the priors' log density at rows ``theta`` (S, D); -inf outside their support."""
        theta = np.atleast_2d(theta)
        with np.errstate(divide="ignore"):
            return sum(np.asarray(p.ln_prob(theta[:, j]), float) for j, p in enumerate(self.priors))

    def attitude_of(self, theta: np.ndarray) -> np.ndarray:
        """(S, 3) yaw, pitch, roll (deg) of rows ``theta``: inferred, or the known offsets."""
        if self.attitude is None:
            return theta[:, [self.names.index(a) for a in ANGLES]]
        return np.tile([getattr(self.attitude, a) for a in ANGLES], (len(theta), 1))

    def stokes(self, theta: np.ndarray) -> np.ndarray:
        """(3, S, T) the target's linear Stokes flux (photons m^-2 s^-1, the sky basis) for rows ``theta`` (S, D).
        All faces' rows at once, face-major, then set, then time."""
        theta = np.atleast_2d(np.asarray(theta, float))
        g, n_sets, n_times, n_faces = self.geometry, len(theta), len(self.geometry.times_utc), len(self.geometry.faces)
        turn = rotations(*self.attitude_of(theta).T)  # (S, 3, 3)
        normals = np.stack([self._normals(face, k, turn) for k, face in enumerate(g.faces)])  # (F, S, 3, T)
        flat = normals.transpose(2, 0, 1, 3).reshape(3, -1)
        repeat = n_faces * n_sets
        to_sun, to_observer = np.tile(g.sun_unit, repeat), np.tile(g.to_observer_unit, repeat)
        theta_i, theta_r, dphi = face_angles(flat, to_sun, to_observer)
        visible = np.tile(g.sunlit & (g.elevation_deg > 0.0), repeat)
        on = (theta_i < 90.0) & (theta_r < 90.0) & visible
        angles = (np.minimum(theta_i, _VIEW_LIMIT_DEG), np.minimum(theta_r, _VIEW_LIMIT_DEG), dphi)
        brdf = self._brdf(theta, angles, n_sets)  # (3, F * S * T)
        area = np.repeat([f.area_m2 for f in g.faces], n_sets * n_times)
        scale = (self._scale * np.cos(np.radians(theta_i)) * area * np.cos(np.radians(theta_r))
                 / np.tile(g.range_km * 1e3, repeat) ** 2)
        psi = rotation_to_sky(flat, to_observer, np.tile(self._sky_s, repeat))
        c, s = np.cos(2 * psi), np.sin(2 * psi)
        light = np.stack([brdf[0], c * brdf[1] + s * brdf[2], -s * brdf[1] + c * brdf[2]]) * np.where(on, scale, 0.0)
        return light.reshape(3, n_faces, n_sets, n_times).sum(axis=1)

    def _normals(self, face, k: int, turn: np.ndarray) -> np.ndarray:
        """(S, 3, T) face ``k``'s unit normals in GCRS under each set's rotation (nadir faces turn; others do not)."""
        g = self.geometry
        if face.orientation != "nadir":
            return np.broadcast_to(g.normals(k), (len(turn),) + g.normals(k).shape)
        body = np.asarray(face.normal, float) / np.linalg.norm(face.normal)
        a = turn @ body  # (S, 3): the normal's orbit-frame components
        x, y, z = self._axes
        return a[:, 0, None, None] * x[None] + a[:, 1, None, None] * y[None] + a[:, 2, None, None] * z[None]

    def _brdf(self, theta: np.ndarray, angles: tuple, n_sets: int) -> np.ndarray:
        """(3, F * S * T) each face's Stokes BRDF at its rows' ``angles`` (theta_i, theta_r, dphi in degrees): the
        unknown material's faces at each set's own parameters and its own geometry (a (S, F_u * T) geometry, one
        row per set: S F_u T evaluations), each fixed material's faces in one evaluation of its own."""
        g = self.geometry
        per_face = len(angles[0]) // len(g.faces)
        out = np.zeros((3, len(angles[0])))
        material = self._held | {n: theta[:, j] for j, n in enumerate(self.names) if n not in ANGLES}
        for key, faces in by_material(g.faces, np.arange(len(g.faces))).items():
            index = np.concatenate([np.arange(k * per_face, (k + 1) * per_face) for k in faces])
            if key is not None:
                model, values = fixed_material(dict(key))
                sub = Geometry(*(a[index] for a in angles))
                out[:, index] = np.asarray(model.evaluate(values, sub, check=False).stokes, float)[:3]
                continue
            out[:, index] = self._paired(material, [a[index] for a in angles], len(faces), n_sets)
        return out

    def _paired(self, material: dict, angles: list, n_faces: int, n_sets: int) -> np.ndarray:
        """(3, F_u * S * T) the unknown material at each set's parameters and that set's rows of ``angles`` (face-major,
        then set, then time): the rows laid out as one geometry row per set, padded to the compiled program's number of
        sets by repeating the last set's rows."""
        per_set = [np.asarray(a, float).reshape(n_faces, n_sets, -1).transpose(1, 0, 2).reshape(n_sets, -1)
                   for a in angles]
        rows = bucket(n_sets)
        if rows > n_sets:
            per_set = [np.pad(a, ((0, rows - n_sets), (0, 0)), mode="edge") for a in per_set]
        stokes = np.asarray(self.model.evaluate(material, Geometry(*per_set), check=False).stokes, float)[:3]
        stokes = stokes[:, :n_sets]  # (3, S, F_u * T): the padded sets' rows off
        return stokes.reshape(3, n_sets, n_faces, -1).transpose(0, 2, 1, 3).reshape(3, -1)
