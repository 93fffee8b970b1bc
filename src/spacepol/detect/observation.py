"""A pass observed with a micro-polarizer camera: P_d(t) per detector over the material's posterior.

Per time: the target's Stokes flux at the aperture (``detect.target``: each draw of the material), the sky at the
target's direction, and the camera turn into mean electrons per pixel of the raw mosaic (``detect.point_source``:
the target through the PSF at places spread over a superpixel, the sky per pixel), and those into each detector's
P_d at the fixed false-alarm rate (``detect.detection``: the matched filters' Neyman-Pearson curves, the DoLP
image's by simulation; checked against simulated frames in tests/test_detection.py and tests/test_observation.py).

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass

import numpy as np

from .detection import DETECTORS, dolp_detection_probability, neyman_pearson
from .point_source import point_source_stamp, superpixel_positions
from .radiometry import background_photon_flux
from .target import bands_over_draws, fixed_material, sky_basis, target_light

# CIE general sky type 12 (clear, low turbidity): gradation a, b and indicatrix c, d, e
CIE_CLEAR = {"a": -1.0, "b": -0.32, "c": 10.0, "d": -3.0, "e": 0.45}


def cie_relative_radiance(view_zenith_deg, scattering_deg, sun_zenith_deg, sky=CIE_CLEAR):
    """L(view) / L(zenith) of the CIE standard general sky."""
    z, chi, zs = (np.radians(np.asarray(v, float)) for v in (view_zenith_deg, scattering_deg, sun_zenith_deg))

    def gradation(zenith):
        return 1.0 + sky["a"] * np.exp(sky["b"] / np.maximum(np.cos(zenith), 1e-3))

    def indicatrix(angle):
        return 1.0 + sky["c"] * (np.exp(sky["d"] * angle) - np.exp(sky["d"] * np.pi / 2)) + sky["e"] * np.cos(angle) ** 2

    return indicatrix(chi) * gradation(z) / (indicatrix(zs) * gradation(0.0))


@dataclass
class Observation:
    """P_d(t) of each detector over the material's draws, with the pass, the target's light and the sky at each time:
    ``p_detect`` {detector: (D, T)}, ``deflection`` {detector: (D, T)}, ``sky_photons_arcsec2`` (T,) (photons m^-2
    s^-1 arcsec^-2), ``sky_dolp`` (T,), ``light`` (detect.target.TargetLight), ``geometry`` (orbit.PassGeometry)."""

    geometry: object
    light: object
    sky_photons_arcsec2: np.ndarray
    sky_dolp: np.ndarray
    deflection: dict
    p_detect: dict
    p_false_alarm: float
    camera: object
    sky_aop_deg: np.ndarray | None = None  # (T,) the sky's AoP in the target's sky basis
    stacked: int = 1  # exposures averaged per time step
    dolp_frames: int = 2000  # simulated frames per draw and time behind the DoLP detector's P_d

    def p_detect_over_pass(self) -> dict:
        """{detector: (D,)} the probability of at least one detection over the times the target is above the
        horizon, per draw (independent frames), and under "false_alarm" the same for a target-free sky."""
        above = self.geometry.elevation_deg > 0
        out = {k: 1.0 - np.prod(1.0 - np.nan_to_num(v[:, above]), axis=1) for k, v in self.p_detect.items()}
        return out | {"false_alarm": 1.0 - (1.0 - self.p_false_alarm) ** int(above.sum())}

    def to_json(self) -> dict:
        """``observe.json``'s content (DESIGN.md's fields, units in the key names)."""
        flux, dolp, aop = (bands_over_draws(v) for v in (self.light.photons_m2_s, self.light.dolp, self.light.aop_deg))
        pd = {k: bands_over_draws(v) for k, v in self.p_detect.items()}
        g = self.geometry
        rows = []
        for j, t in enumerate(g.times_utc):
            def q(a):
                return {"median": _num(a[1, j]), "q05": _num(a[0, j]), "q95": _num(a[2, j])}

            rows.append({"time_utc": t.isoformat().replace("+00:00", "Z"), "range_km": float(g.range_km[j]),
                         "elevation_deg": float(g.elevation_deg[j]), "azimuth_deg": float(g.azimuth_deg[j]),
                         "sun_elevation_deg": float(g.sun_elevation_deg[j]), "phase_angle_deg": float(g.phase_angle_deg[j]),
                         "sunlit": bool(g.sunlit[j]), "sky_state": g.sky[j],
                         "target": {"flux": q(flux), "dolp": q(dolp), "aop_deg": q(aop)},
                         "sky": {"radiance": float(self.sky_photons_arcsec2[j]),
                                 "dolp": float(self.sky_dolp[j])},
                         "p_detect": {k: q(v) for k, v in pd.items()}})
        over_pass = self.p_detect_over_pass()
        false_alarm = over_pass.pop("false_alarm")
        lat, lon, height = g.site
        return {"satellite": g.satellite, "site": {"lat_deg": lat, "lon_deg": lon, "height_m": height},
                "window": {"start_utc": rows[0]["time_utc"], "end_utc": rows[-1]["time_utc"], "steps": len(rows)},
                "camera": {k: v for k, v in vars(self.camera).items() if k not in ("layout", "exposure_set")}
                | {"layout": self.camera.layout.name},
                "detectors": list(self.p_detect), "times": rows, "p_false_alarm": self.p_false_alarm,
                "exposures_per_step": self.stacked, "dolp_frames_per_draw": self.dolp_frames,
                "units": {"flux": "photons m^-2 s^-1 at the aperture, in the band", "radiance": "photons m^-2 s^-1 arcsec^-2",
                          "aop_deg": "deg in the sky basis, from the horizontal"},
                "over_pass": {"steps_above_horizon": int(np.sum(g.elevation_deg > 0)), "p_false_alarm": false_alarm,
                              "p_detect": {k: dict(zip(("q05", "median", "q95"), (_num(x) for x in np.nanpercentile(v, [5, 50, 95]))))
                                           for k, v in over_pass.items()}}}


def _num(x) -> float | None:
    return None if not np.isfinite(x) else float(x)


def observe_pass(geometry, model, draws: dict, camera, band_um=(1.5, 1.8), p_false_alarm: float = 1e-3,
                 sky_magnitude_zenith: float = 5.40, p_max: float = 0.7, stamp_pixels: int = 18,
                 rng: np.random.Generator | None = None, stacked: int = 1, dolp_frames: int = 2000,
                 positions_per_side: int = 4, progress: bool = False) -> Observation:
    """P_d over the pass ``geometry`` (with the target's faces) for the material ``model`` at ``draws`` seen by
    ``camera`` (``camera.sensor.Camera``), each time step ``stacked`` exposures averaged. Each detector's P_d is
    the mean over ``positions_per_side``^2 places of the target within a superpixel (``detect.point_source``): the
    matched filters' from their Neyman-Pearson curves, the DoLP image's by simulation (``rng``; ``dolp_frames``
    frames per draw and time, so a binomial error of at most 0.5 / sqrt(dolp_frames)). ``deflection`` holds the
    matched filters' deflections averaged over the places."""
    rng = np.random.default_rng(0) if rng is None else rng
    light = target_light(geometry, model, draws, band_um)
    sky_photons = sky_photons_at(geometry, sky_magnitude_zenith)
    sky_dolp = sky_dolp_at(geometry, p_max)
    sky_aop = _sky_aop(geometry)
    positions = superpixel_positions(stamp_pixels, positions_per_side)
    per_place = max(dolp_frames // len(positions), 1)
    n_draws, n_times = light.photons_m2_s.shape
    deflection = {k: np.full((n_draws, n_times), np.nan) for k in ("intensity", "stokes")}
    p_detect = {k: np.full((n_draws, n_times), np.nan) for k in DETECTORS}
    started = time.perf_counter()
    for j in range(n_times):
        if progress and j and j % max(1, n_times // 10) == 0:
            print(f"  observe: {j}/{n_times} times, {time.perf_counter() - started:.0f} s", file=sys.stderr)
        if geometry.elevation_deg[j] <= 0:
            continue
        sky = sky_stokes_per_pixel(camera, sky_photons[j], sky_dolp[j], sky_aop[j])
        stokes = (light.stokes_w_m2[:3, :, j] * light.photons_per_joule).T  # (D, 3) photons m^-2 s^-1
        lit = np.all(np.isfinite(stokes), axis=1) & (np.nan_to_num(stokes[:, 0]) > 0)
        stokes = np.where(lit[:, None], stokes, 0.0)
        for k in DETECTORS:
            p_detect[k][:, j] = 0.0
        deflection["intensity"][:, j] = deflection["stokes"][:, j] = 0.0
        for centre in positions:
            stamp = point_source_stamp(camera, sky, centre, stamp_pixels)
            if np.max(stamp.sky_e) > camera.full_well_e:
                seen = np.zeros(n_draws, bool)  # the sky alone fills the wells
            else:
                seen = lit & ~stamp.saturated(stokes)  # a saturated target: the filters see a flat top
            d = stamp.deflections(stokes, stacked)
            for k in ("intensity", "stokes"):
                d_k = np.where(seen, d[k], 0.0)
                deflection[k][:, j] += d_k / len(positions)
                p_detect[k][:, j] += neyman_pearson(d_k, p_false_alarm) / len(positions)
            p_dolp = np.full(n_draws, p_false_alarm)
            if seen.any():
                sky_flux, target_flux, sd = stamp.dolp_fluxes(stokes[seen], stacked)
                p_dolp[seen] = dolp_detection_probability(sky_flux, target_flux, sd, p_false_alarm, rng,
                                                          target_frames=per_place)
            p_detect["dolp"][:, j] += p_dolp / len(positions)
    return Observation(geometry, light, sky_photons, sky_dolp, deflection, p_detect, p_false_alarm, camera, sky_aop,
                       stacked=stacked, dolp_frames=per_place * len(positions))


def sky_stokes_per_pixel(camera, radiance_photons_m2_s_arcsec2: float, dolp: float, aop_deg: float) -> np.ndarray:
    """(3,) the sky's linear Stokes photon rate on one pixel of ``camera`` before its analyser (photons s^-1)."""
    rate = radiance_photons_m2_s_arcsec2 * camera.pixel_scale_arcsec**2 * camera.transmittance * camera.aperture_area_m2
    psi = np.radians(aop_deg)
    return rate * np.array([1.0, dolp * np.cos(2 * psi), dolp * np.sin(2 * psi)])


def sky_dolp_at(geometry, p_max: float = 0.7) -> np.ndarray:
    """(T,) the sky's DoLP at the target's direction: single Rayleigh scattering scaled by ``p_max``."""
    from ..skylight.rayleigh import RayleighSky

    sun = (90.0 - geometry.sun_elevation_deg, geometry.sun_azimuth_deg)
    return np.asarray(RayleighSky(p_max).dop(90.0 - geometry.elevation_deg, geometry.azimuth_deg, sun), float)


def sky_photons_at(geometry, sky_magnitude_zenith: float = 5.40) -> np.ndarray:
    """(T,) the sky's radiance at the target's direction (photons m^-2 s^-1 arcsec^-2; 0 after sunset)."""
    view_zenith = 90.0 - geometry.elevation_deg
    scattering = np.degrees(np.arccos(np.clip(np.sum(geometry.sun_unit * -geometry.to_observer_unit, axis=0), -1, 1)))
    relative = cie_relative_radiance(np.minimum(view_zenith, 89.0), scattering, 90.0 - geometry.sun_elevation_deg)
    return background_photon_flux(sky_magnitude_zenith) * relative * (geometry.sun_elevation_deg > -0.833)


def auto_exposure_s(camera, geometry, sky_magnitude_zenith: float = 5.40, fill: float = 0.5,
                    longest_s: float = np.inf) -> float:
    """The exposure an observer would set: the brightest sky the target is seen against (above the horizon) fills
    ``fill`` of the full well, at most ``longest_s`` (a time step: a frame cannot outlast it; a dark twilight sky
    would ask for minutes), rounded down to 1, 2 or 5 x 10^k s."""
    above = geometry.elevation_deg > 0
    sky = sky_photons_at(geometry, sky_magnitude_zenith)[above] if above.any() else np.zeros(1)
    rate = camera.quantum_efficiency * camera.transmittance * camera.aperture_area_m2 * camera.pixel_scale_arcsec**2 \
        * 0.5 * camera.transmissions[0] * float(np.max(sky)) + camera.dark_current_e_per_s
    seconds = min(fill * camera.full_well_e / rate, longest_s)
    decade = 10.0 ** np.floor(np.log10(seconds))
    return float(max(step * decade for step in (1.0, 2.0, 5.0) if step * decade <= seconds))


def camera_given(camera):
    """The camera a pass is seen with: a TOML file's [camera], a ``camera.sensor.Camera`` as it is, or the default
    (None) with its exposure left for the pass to set (``exposed_for``)."""
    from pathlib import Path

    from ..camera.sensor import Camera, camera_from_toml

    if camera is None:
        return Camera(exposure_set=False)
    return camera_from_toml(camera) if isinstance(camera, (str, Path)) else camera


def exposed_for(camera, geometry, sky_magnitude_zenith: float, step_s: float = np.inf):
    """``camera`` as it is where its exposure was given; else with the exposure that keeps the brightest sky of the
    pass at half the well, no longer than a time step ``step_s`` (``auto_exposure_s``)."""
    from dataclasses import replace

    if camera.exposure_set:
        return camera
    seconds = auto_exposure_s(camera, geometry, sky_magnitude_zenith, longest_s=step_s)
    return replace(camera, exposure_s=seconds, exposure_set=True)


def _sky_aop(geometry) -> np.ndarray:
    """The sky's AoP (deg) at the target's direction in the target's sky basis (``target.sky_basis``): single
    scattering's E-vector, perpendicular to the sun - view plane."""
    s_ref, p_ref = sky_basis(geometry)
    e = np.cross(geometry.sun_unit.T, geometry.to_observer_unit.T).T
    return np.degrees(np.arctan2(np.sum(e * p_ref, axis=0), np.sum(e * s_ref, axis=0)))


def observe_result(result, tle, site: tuple[float, float, float], start, end, *, step_s: float = 10.0,
                   satellite: str | None = None, target=None, camera=None, draws: int = 200,
                   rng: np.random.Generator | None = None, p_false_alarm: float = 1e-3, band_um=(1.5, 1.8),
                   progress: bool = False, exposures_per_step: int = 1, sky_magnitude_zenith: float = 5.40,
                   p_max: float = 0.7) -> tuple[Observation, list[str]]:
    """A run's material (``result``: an ``infer.Result``, ``draws`` of its posterior) on a satellite's pass: the
    elements of ``tle`` (``satellite`` picks one), the faces of ``target`` (a TOML file, a list of ``orbit.Face``, or
    the default cube with a panel), seen by ``camera`` (a TOML file, a ``Camera``, or the default, its exposure set
    from the pass where not given), under a sky of ``sky_magnitude_zenith`` mag arcsec^-2 at the zenith polarized up
    to ``p_max``. Returns the Observation and the report's sentences on what it assumed."""
    from pathlib import Path

    from ..orbit import default_faces, pass_geometry, read_tle, target_faces
    from .contrast import material_samples
    from .scenario import default_scenario

    rng = np.random.default_rng(0) if rng is None else rng
    # a target file's attitude offsets turn its body faces, as they fly
    faces = default_faces() if target is None else target_faces(target) if isinstance(target, (str, Path)) else list(target)
    camera = camera_given(camera)
    for face in faces:  # a face's own material is checked before the pass is computed
        if face.material is not None:
            fixed_material(face.material)
    element_set = read_tle(tle, satellite)
    geometry = pass_geometry(element_set, site, start, end, step_s, faces)
    camera = exposed_for(camera, geometry, sky_magnitude_zenith, step_s)
    scenario = default_scenario()
    scenario.instrument.update(band_low_um=float(band_um[0]), band_high_um=float(band_um[1]))
    inner, params, material = material_samples(result.model, result.samples(), scenario,
                                               result.summary.model_spec)
    size = max(np.size(v) for v in params.values())
    pick = rng.choice(size, min(draws, size), replace=False)
    chosen = {k: np.asarray(v)[pick] if np.size(v) == size else v for k, v in params.items()}  # fixed values as they are
    if progress:
        print(f"observe: {element_set.name}, {len(geometry.times_utc)} times, {len(faces)} faces, {len(pick)} draws of "
              f"{result.summary.model}", file=sys.stderr)
    observation = observe_pass(geometry, inner, chosen, camera, band_um, p_false_alarm, sky_magnitude_zenith, p_max,
                               rng=rng, stacked=exposures_per_step, progress=progress)
    assumptions = [
        f"Satellite {element_set.name} from {element_set.source} (SGP4, skyfield), site {site[0]:.4f}, {site[1]:.4f} deg, "
        f"{site[2]:g} m; {len(geometry.times_utc)} times every {step_s:g} s.",
        f"Target: {len(faces)} faces ({', '.join(f'{f.name} {f.area_m2:g} m^2 {f.orientation}' + _material_words(f) for f in faces)}); "
        "shadows between faces and light reflected between them are left out.",
        f"Material: {len(pick)} draws of the posterior of {result.summary.model}; {material['rule']}.",
        f"Sun: a 5772 K black body at 1 au in {band_um[0]:g}-{band_um[1]:g} um. Sky: CIE clear sky (type 12) scaled to "
        f"{sky_magnitude_zenith:g} mag arcsec^-2 at the zenith (default 5.40, what the paper's Table 3 implies), single "
        f"Rayleigh scattering's polarization with P_max {p_max:g}.",
        f"Camera: {camera.layout.name}, extinction ratio {camera.extinction_ratio:g}, QE {camera.quantum_efficiency:g}, read "
        f"noise {camera.read_noise_e:g} e, exposure {camera.exposure_s:g} s (set where not given: the brightest sky of the "
        f"pass at half the full well), {camera.pixel_scale_arcsec:g} arcsec pixels, "
        f"PSF FWHM {camera.psf_fwhm_pixels:g} px, aperture {camera.aperture_area_m2:g} m^2.",
        f"Detectors: intensity and Stokes (four analyser channels) matched filters, P_d from their Neyman-Pearson curves "
        f"at P_fa = {p_false_alarm:g}; the DoLP image (|DoLP - the sky's DoLP| of the PSF-weighted flux), threshold and "
        f"P_d by simulation ({observation.dolp_frames} frames per draw and time). Each averaged over 16 places of the "
        "target within a superpixel; all three checked against simulated raw frames in the tests. "
        f"{exposures_per_step} exposure(s) averaged per time; P_d over the pass assumes independent frames.",
    ]
    return observation, assumptions


def _material_words(face) -> str:
    if face.material is None:
        return ""
    values = ", ".join(f"{k} {v:g}" for k, v in face.material.items() if k != "model")
    return f" of fixed {face.material['model']} ({values})"
