"""The target's light at the aperture over a pass: the sunlit faces of a satellite, each with its area, orientation
and a material (a run's posterior draws or fixed parameters), give the Stokes flux of the reflected sunlight.

For unpolarized sunlight of band irradiance E on a face of area A at incidence theta_i, seen at reflection angle
theta_r from range R, the Stokes flux at the aperture is

    F = E cos(theta_i) A cos(theta_r) / R^2 x S(theta_i, theta_r, dphi)     (W m^-2, and photons m^-2 s^-1)

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..physics.geometry import Geometry

SUN_TEMPERATURE_K = 5772.0
SUN_RADIUS_KM = 695_700.0
AU_KM = 149_597_870.7
_H, _C, _K = 6.62607015e-34, 299_792_458.0, 1.380649e-23


def solar_band(band_low_um: float, band_high_um: float, temperature_k: float = SUN_TEMPERATURE_K) -> tuple[float, float]:
    """(irradiance W m^-2, photon flux photons m^-2 s^-1) of the sun at 1 au in the band (a black body)."""
    if not 0 < band_low_um < band_high_um:
        raise ParameterError(f"band {band_low_um:g}-{band_high_um:g} um: need 0 < low < high")
    lam = np.linspace(band_low_um, band_high_um, 2001) * 1e-6  # m
    radiance = 2 * _H * _C**2 / lam**5 / np.expm1(_H * _C / (lam * _K * temperature_k))  # W m^-2 sr^-1 m^-1
    dilution = np.pi * (SUN_RADIUS_KM / AU_KM) ** 2  # the sun's solid angle x its Lambertian pi
    irradiance = dilution * np.trapezoid(radiance, lam)
    photons = dilution * np.trapezoid(radiance * lam / (_H * _C), lam)
    return float(irradiance), float(photons)


@dataclass
class TargetLight:
    """The target's light at the aperture over a pass, for D material draws at T times: ``stokes_w_m2`` (4, D, T) in
    the sky basis (S1 > 0 horizontal), ``photons_m2_s`` (D, T) (S0 in photons), ``dolp`` and ``aop_deg`` (D, T;
    NaN where no light comes), ``lit_faces`` (T,) how many faces send light, ``photons_per_joule`` the band's photons
    per joule of sunlight (Stokes W m^-2 -> photons m^-2 s^-1)."""

    stokes_w_m2: np.ndarray
    photons_m2_s: np.ndarray
    dolp: np.ndarray
    aop_deg: np.ndarray
    lit_faces: np.ndarray
    photons_per_joule: float


def bands_over_draws(values: np.ndarray) -> np.ndarray:
    """(3, T) the 5 %, 50 % and 95 % quantiles over the draws (axis 0) at each time, NaN where no draw has a value."""
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a time with no light in any draw: NaN, said so
        return np.nanpercentile(values, [5, 50, 95], axis=0)


def sky_basis(geometry) -> tuple[np.ndarray, np.ndarray]:
    """(s, p) unit vectors (3, T) of the observer's sky basis for the light arriving along ``to_observer_unit``:
    s = u x d horizontal (u the site's geocentric vertical), p = d x s; AoP runs from s towards p."""
    d = geometry.to_observer_unit
    up = geometry.position_km + geometry.range_km * d
    up = up / np.linalg.norm(up, axis=0)
    s = np.cross(up.T, d.T).T
    s /= np.linalg.norm(s, axis=0)
    return s, np.cross(d.T, s.T).T


def rotation_to_sky(normals: np.ndarray, to_observer: np.ndarray, s_sky: np.ndarray) -> np.ndarray:
    """The angle (rad) that turns a face's s vector (n x d) into the sky's ``s_sky`` about d, per time (3, T) inputs."""
    s_face = np.cross(normals.T, to_observer.T).T
    s_face /= np.maximum(np.linalg.norm(s_face, axis=0), 1e-300)
    return np.arctan2(np.sum(np.cross(s_face.T, s_sky.T).T * to_observer, axis=0), np.sum(s_face * s_sky, axis=0))


def target_light(geometry, model, draws: dict, band_um: tuple[float, float], irradiance_w_m2: float | None = None) -> TargetLight:
    """The light of the target (``geometry``: a ``orbit.PassGeometry`` with faces) for the material ``model`` at the
    parameter draws ``draws`` ({name: (D,) or scalar}; the rest at the model's defaults) in the band ``band_um``.
    ``irradiance_w_m2`` overrides the black-body sun's band irradiance (the photon flux scales with it)."""
    if not geometry.faces:
        raise ParameterError("target: no faces (give each its area, orientation and normal)")
    irradiance, photons = solar_band(*band_um)
    if irradiance_w_m2 is not None:
        photons *= irradiance_w_m2 / irradiance
        irradiance = irradiance_w_m2
    names = {p.name for p in model.parameters} if model is not None else set()  # None: every face has its material
    params = {k: np.atleast_1d(np.asarray(v, float)) for k, v in draws.items() if k in names}
    n_draws = max((len(v) for v in params.values()), default=1)
    n_times = len(geometry.times_utc)
    s_sky, _ = sky_basis(geometry)
    stokes = np.zeros((4, n_draws, n_times))
    on = geometry.lit & geometry.seen  # (T, faces)
    lit_faces = on.sum(axis=1)
    times, faces = np.nonzero(on)
    if times.size:
        g = Geometry(geometry.theta_i_deg[times, faces], geometry.theta_r_deg[times, faces], geometry.dphi_deg[times, faces])
        sr = np.zeros((4, n_draws, times.size))
        # every (time, face) of one material in one evaluation of its model: the run's, or a face's fixed one
        for material, rows in by_material(geometry.faces, faces).items():
            face_model, face_params = (model, params) if material is None else fixed_material(material)
            sub = Geometry(g.theta_i[rows], g.theta_r[rows], g.dphi[rows])
            sr[:, :, rows] = np.asarray(face_model.evaluate(face_params, sub).stokes, float).reshape(4, -1, rows.size)
        area = np.array([f.area_m2 for f in geometry.faces])[faces]
        ti, tr = np.radians(geometry.theta_i_deg[times, faces]), np.radians(geometry.theta_r_deg[times, faces])
        scale = irradiance * np.cos(ti) * area * np.cos(tr) / (geometry.range_km[times] * 1e3) ** 2
        normals = np.stack([geometry.normals(k) for k in range(len(geometry.faces))], axis=-1)  # (3, T, faces)
        psi = rotation_to_sky(normals[:, times, faces], geometry.to_observer_unit[:, times], s_sky[:, times])
        c, sn = np.cos(2 * psi), np.sin(2 * psi)
        rotated = np.stack([sr[0], c * sr[1] + sn * sr[2], -sn * sr[1] + c * sr[2], sr[3]]) * scale
        for component in range(4):  # faces seen at the same time add up
            np.add.at(stokes[component], (slice(None), times), np.broadcast_to(rotated[component], (n_draws, times.size)))
    dolp, aop = linear_polarization(*stokes[:3])
    return TargetLight(stokes, stokes[0] * photons / irradiance, dolp, aop, lit_faces, photons / irradiance)


def linear_polarization(s0, s1, s2) -> tuple[np.ndarray, np.ndarray]:
    """(DoLP, AoP in degrees) of linear Stokes components (any shape), NaN where no light comes (S0 <= 0)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        lit = s0 > 0
        dolp = np.where(lit, np.hypot(s1, s2) / np.where(lit, s0, 1.0), np.nan)
        aop = np.where(lit, 0.5 * np.degrees(np.arctan2(s2, s1)), np.nan)
    return dolp, aop


def by_material(faces, face_index: np.ndarray) -> dict:
    """{material key (None: the run's; else the fixed material's items): rows of ``face_index`` made of it}."""
    keys = [None if f.material is None else tuple(sorted(f.material.items())) for f in faces]
    groups: dict = {}
    for row, k in enumerate(face_index):
        groups.setdefault(keys[k], []).append(row)
    return {k: np.array(v) for k, v in groups.items()}


def fixed_material(material) -> tuple:
    """(Model, parameters) of a face's fixed material: its ``model`` spec and values (the rest at their defaults);
    an unknown model or parameter is one line."""
    from ..physics.model import Model

    values = dict(material)
    spec = values.pop("model")
    model = Model.from_string(spec)
    names = {p.name for p in model.parameters}
    unknown = sorted(set(values) - names)
    if unknown:
        raise ParameterError(f"face material {spec}: no parameter {', '.join(unknown)} (it has {', '.join(sorted(names))})")
    return model, {k: float(v) for k, v in values.items()}
