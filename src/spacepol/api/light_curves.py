"""A satellite's polarimetric light curve: ``synth_pass`` renders one through the chain (the pass's geometry, the
target's faces and their materials, the sun, the sky and a micro-polarizer camera's noise)."""

from __future__ import annotations

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
    from dataclasses import replace

    from ..camera.sensor import Camera, camera_from_toml
    from ..detect.light_curve_synth import synthesized_light_curve
    from ..detect.observation import auto_exposure_s
    from ..detect.target import fixed_material
    from ..io.light_curve import write_light_curve
    from ..orbit import attitude_from_toml, faces_from_toml, pass_geometry, read_tle, turned
    from ..orbit.pass_geometry import time_steps

    if out is not None:
        out = Path(out)
        if out.exists() and out.is_dir():
            raise ParameterError(f"--out {out}: a folder; give the CSV file's name")
        if not out.parent.is_dir():
            raise ParameterError(f"--out {out}: its folder {out.parent} does not exist")
    site = parse_site(site)
    if not (np.isfinite(step_s) and step_s > 0):
        raise ParameterError(f"--step {step_s}: need a number of seconds > 0")
    time_steps(start, end, step_s)
    if exposures_per_step is not None and not (isinstance(exposures_per_step, int) and exposures_per_step >= 1):
        raise ParameterError(f"--exposures {exposures_per_step}: need a whole number of at least 1")
    faces = faces_from_toml(target)
    attitude = attitude_from_toml(target)
    bare = [f.name for f in faces if f.material is None]
    if bare:
        raise ParameterError(f"--target {target}: face {', '.join(bare)} has no material; synth-pass renders faces of "
                             "known materials (give each a material = {model = \"...\", ...} table)")
    for face in faces:
        fixed_material(face.material)
    if attitude is not None:
        faces = turned(faces, attitude)
    cam = Camera(exposure_set=False) if camera is None else camera_from_toml(camera) if isinstance(camera, (str, Path)) else camera
    geometry = pass_geometry(read_tle(tle, satellite), site, start, end, step_s, faces)
    if not cam.exposure_set:
        cam = replace(cam, exposure_s=auto_exposure_s(cam, geometry, sky_magnitude_zenith), exposure_set=True)
    frames = exposures_per_step or max(1, int(step_s // cam.exposure_s))
    curve = synthesized_light_curve(geometry, cam, np.random.default_rng(seed), band_um, sky_magnitude_zenith, frames)
    if out is not None:
        write_light_curve(out, curve)
    return curve
