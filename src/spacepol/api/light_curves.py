"""A satellite's polarimetric light curve: ``synth_pass`` renders one through the chain (the pass's geometry, the
target's faces and their materials, the sun, the sky and a micro-polarizer camera's noise); ``invert_lightcurve``
reads the material and the attitude back from one."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..io.light_curve import LightCurve
from .inputs import parse_site


def synth_pass(tle, site, start, end, *, target, step_s: float = 10.0, satellite: str | None = None, camera=None,
               seed: int = 0, band_um=(1.5, 1.8), sky_magnitude_zenith: float = 5.40, exposures_per_step: int | None = None,
               out=None) -> LightCurve:
    """The light curve a camera would measure of the satellite of ``tle`` over ``site`` ("LAT,LON[,HEIGHT_M]" or a
    tuple) from ``start`` to ``end`` (ISO 8601 with offset) every ``step_s`` seconds: ``target`` a TOML file whose
    every face has a ``material`` table (its optional top-level ``attitude`` offsets the nominal orientation),
    ``camera`` a TOML file's [camera], a ``camera.sensor.Camera`` or the default (its exposure set from the pass's
    sky where not given), the noise drawn with ``seed``, each time the mean of ``exposures_per_step`` frames (default:
    as many as fill the step, a camera running through it). Only the times when the satellite is above the horizon,
    sunlit and turning a lit face to the site are kept. With ``out`` the CSV (``io.light_curve``) is written there."""
    from ..detect.light_curve_synth import synthesized_light_curve
    from ..detect.observation import camera_given, exposed_for
    from ..detect.target import fixed_material
    from ..io.light_curve import write_light_curve
    from ..orbit import pass_geometry, read_tle, target_faces
    from ..orbit.pass_geometry import time_steps

    if out is not None:
        from ..io.output import check_output_file

        out = check_output_file(out)
    site = parse_site(site)
    time_steps(start, end, step_s)  # the window and its step, checked before any work
    if exposures_per_step is not None and not (isinstance(exposures_per_step, int) and exposures_per_step >= 1):
        raise ParameterError(f"--exposures {exposures_per_step}: need a whole number of at least 1")
    faces = target_faces(target)  # turned by the file's attitude offsets, where it has them
    bare = [f.name for f in faces if f.material is None]
    if bare:
        raise ParameterError(f"--target {target}: face {', '.join(bare)} has no material; synth-pass renders faces of "
                             "known materials (give each a material = {model = \"...\", ...} table)")
    for face in faces:
        fixed_material(face.material)
    cam = camera_given(camera)
    geometry = pass_geometry(read_tle(tle, satellite), site, start, end, step_s, faces)
    cam = exposed_for(cam, geometry, sky_magnitude_zenith, step_s)
    frames = exposures_per_step or max(1, int(step_s // cam.exposure_s))
    curve = synthesized_light_curve(geometry, cam, np.random.default_rng(seed), band_um, sky_magnitude_zenith, frames)
    if out is not None:
        write_light_curve(out, curve)
    return curve


def invert_lightcurve(curve, tle, site, start, end, *, target, materials, step_s: float = 10.0,
                      observables=None, satellite: str | None = None, seed: int = 0, live: int = 500,
                      band_um=(1.5, 1.8), out=None, progress: bool = False):
    """A satellite's material and attitude from its light curve (``curve``: a LightCurve or its CSV file), measured
    from ``site`` in the window ``start``-``end`` (its times must lie inside it; ``step_s`` the window's grid, checked)
    of the satellite of ``tle``. ``target``: a TOML file of faces; those without a material table are made of the
    unknown material, and a top-level ``attitude`` table fixes the offsets (inferred, within 60 deg, where absent).
    For each name of ``materials`` (``detect.materials.LIBRARY``) the joint posterior of its parameters and the
    offsets and its evidence (nested sampling with ``live`` live points), ranked by ELPD-LOO over ``observables`` (flux, dolp, aop; default all the file
    holds). Returns the ``detect.light_curve_inversion.LightCurveInversion``; with ``out`` lightcurve.json,
    light_curve.png, attitude_corner.png and report.html."""
    from ..detect.light_curve_inversion import LightCurveInversion, MaterialFit, check_observables, fit_material
    from ..detect.light_curve_model import LightCurveModel
    from ..orbit import read_target

    if out is not None:
        from ..io.output import check_output_dir

        out = check_output_dir(Path(out))
    site = parse_site(site)
    if not (isinstance(live, int) and live >= 50):
        raise ParameterError(f"--live {live}: need a whole number of at least 50")
    candidates = _candidates(materials, band_um)  # an unknown name: one line, before any work
    curve = _curve_in_window(curve, start, end, step_s)
    observables = check_observables(curve, observables)
    faces, attitude = read_target(target)
    geometry, element_set = _visible_geometry(curve, tle, satellite, site, faces)
    rng = np.random.default_rng(seed)
    key = _run_key(curve, tle, satellite, site, target, observables, live, seed, band_um)
    fits = []
    for candidate in candidates:
        stream = rng.spawn(1)[0]  # drawn for every candidate, fitted or kept, so each gets the same stream
        kept = None if out is None else MaterialFit.load(out / "fits" / f"{candidate.name}.npz", key)
        if kept is not None:
            fits.append(kept)
            continue
        if progress:
            print(f"lightcurve: {candidate.name} ({candidate.description})", file=sys.stderr)
        model = LightCurveModel(geometry, candidate, attitude, band_um)
        fits.append(fit_material(model, curve, observables, stream, live=live, progress=progress))
        if out is not None:  # an interrupted run keeps the materials it finished
            (out / "fits").mkdir(parents=True, exist_ok=True)
            fits[-1].save(out / "fits" / f"{candidate.name}.npz", key)
    notes = _assumptions(element_set, site, curve, start, end, faces, attitude, band_um, observables, live)
    inversion = LightCurveInversion(curve, fits, observables, notes)
    if out is not None:
        from ..report.light_curve_report import write_light_curve_report

        write_light_curve_report(inversion, out)
    return inversion


def _run_key(curve, tle, satellite, site, target, observables, live, seed, band_um) -> str:
    """A digest of everything a material's fit depends on: a saved fit is reused only for the same inputs."""
    import hashlib

    parts = [curve.rows(), Path(tle).read_text(encoding="utf-8", errors="replace"), satellite, list(site),
             Path(target).read_text(encoding="utf-8", errors="replace"), observables, live, seed, list(band_um)]
    return hashlib.sha256(repr(parts).encode()).hexdigest()


def _candidates(materials, band_um) -> list:
    from ..detect.materials import material

    names = [m.strip() for m in (materials.split(",") if isinstance(materials, str) else materials) if m.strip()]
    if not names:
        raise ParameterError("--materials: name at least one material")
    return [material(name, 0.5 * (band_um[0] + band_um[1])) for name in names]


def _curve_in_window(curve, start, end, step_s: float) -> LightCurve:
    """The light curve (read where a path), each of its times inside the window; else one line."""
    from ..io.light_curve import read_light_curve
    from ..orbit.pass_geometry import time_steps
    from ..skylight.sun import parse_time

    window = time_steps(start, end, step_s)
    if not isinstance(curve, LightCurve):
        curve = read_light_curve(curve)
    last = parse_time(end) if isinstance(end, str) else end
    outside = [t for t in curve.times_utc if not window[0] <= t <= last]
    if outside:
        raise ParameterError(f"{curve.source}: time {outside[0]:%Y-%m-%dT%H:%M:%SZ} lies outside the pass window "
                             f"{start} - {end}")
    return curve


def _visible_geometry(curve, tle, satellite, site, faces):
    """(the pass's geometry at the curve's times, the element set); one line where the satellite cannot be seen at
    any measured time (below the horizon or in Earth's shadow), or at some of them."""
    from ..orbit import read_tle
    from ..orbit.pass_geometry import pass_geometry_at

    element_set = read_tle(tle, satellite)
    geometry = pass_geometry_at(element_set, site, curve.times_utc, faces)
    hidden = np.flatnonzero(~((geometry.elevation_deg > 0) & geometry.sunlit))
    if hidden.size == len(curve):
        raise ParameterError(f"{element_set.name}: below the horizon or in Earth's shadow at every time of "
                             f"{curve.source}: the elements, the site or the times do not belong together")
    if hidden.size:
        raise ParameterError(f"{curve.source}: at {curve.times_utc[hidden[0]]:%Y-%m-%dT%H:%M:%SZ} (and {hidden.size - 1} "
                             f"more) {element_set.name} is below the horizon or in Earth's shadow, yet light was "
                             "measured: the elements, the site or the times do not belong together")
    return geometry, element_set


def _assumptions(element_set, site, curve, start, end, faces, attitude, band_um, observables, live) -> list[str]:
    from ..detect.light_curve_model import ATTITUDE_LIMIT_DEG

    unknown_faces = [f.name for f in faces if f.material is None]
    return [
        f"Satellite {element_set.name} from {element_set.source} (SGP4, skyfield), site {site[0]:.4f}, {site[1]:.4f} deg, "
        f"{site[2]:g} m; {len(curve)} measured times between {start} and {end}.",
        f"Target: {len(faces)} faces; of the unknown material: {', '.join(unknown_faces) or 'none'}; shadows between "
        "faces and light reflected between them are left out.",
        ("Attitude: offsets known from the target file: " + ", ".join(f"{k} {v:g}" for k, v in attitude.to_json().items())
         if attitude is not None else f"Attitude: yaw, pitch and roll offsets inferred, each uniform within "
         f"{ATTITUDE_LIMIT_DEG:g} deg of the nominal orientation (z-y-x about the orbit frame)."),
        f"Sun: a 5772 K black body at 1 au in {band_um[0]:g}-{band_um[1]:g} um; fitted: {', '.join(observables)} with the "
        "file's errors (the flux Gaussian; DoLP and AoP as measured from Stokes q and u with Gaussian errors, unbiased "
        "where the polarization is near its noise).",
        f"Posterior and evidence: nested sampling (nautilus, {live} live points) from the whole prior, every mode it "
        "finds weighted by its mass; ELPD-LOO by PSIS over the measured points.",
    ]
