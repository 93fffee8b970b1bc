"""From a posterior to the sky: ``contrast`` (the paper's Table 3 as distributions), ``observe`` (a satellite's
pass), ``frame`` (a micro-polarizer frame as Stokes maps) and ``sky`` (the sun and the sky's polarization)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ParameterError, UnknownNameError
from ..infer.result import Result
from .inputs import parse_direction, finite_number, parse_site


@dataclass
class Contrast:
    """A run's posterior in a detection scenario (the paper's Table 3 as distributions): ``rows`` per case with
    the median and 5-95 % interval of target DOP, sky DOP, limiting magnitude and the contrasts; ``material`` (the
    wavelength and the rule that gave n, k there); ``draws`` {case: {quantity: draws}}; ``content`` is
    contrast.json's whole record."""

    content: dict
    draws: dict

    @property
    def rows(self) -> list[dict]:
        """One record per scenario case."""
        return self.content["rows"]

    @property
    def material(self) -> dict:
        """The wavelength the target is seen at, the run's wavelengths and the rule that gave n and k there."""
        return self.content["material"]

    def to_json(self) -> dict:
        """contrast.json's content."""
        return self.content


def contrast(result: Result | str | Path, scenario=None, out=None, *, reading: str = "corrected", draws: int = 20000,
             seed: int = 0, extrapolate: bool = False) -> Contrast:
    """Propagate a Result's posterior (or that of a run folder, ``Result.load``) into target DOP, sky DOP, limiting
    magnitude and contrasts in ``scenario`` (a TOML path, a dict laid out as that file, or a Scenario; default the
    paper's Table 3). Over several wavelengths n and k at the scenario's wavelength come from the Result's own model
    (dispersion law or interpolation; beyond the measured range only with ``extrapolate``). With ``out`` the files of
    ``invert-mcmc contrast`` are written there; the report names the run by its folder where one was given."""
    from ..detect.contrast import contrast_of
    from ..detect.scenario import default_scenario, read_scenario, scenario_from_dict

    if scenario is None:
        scenario = default_scenario()
    elif isinstance(scenario, (str, Path)):
        scenario = read_scenario(scenario)
    elif isinstance(scenario, dict):
        scenario = scenario_from_dict(scenario)
    if out is not None:
        from ..io.output import check_output_dir

        out = check_output_dir(Path(out))  # before the work
    label = None
    if isinstance(result, (str, Path)):
        label, result = str(result), Result.load(result)
    content, per_case = contrast_of(result, scenario, seed, draws, reading, extrapolate)
    if out is not None:
        from ..report.contrast_report import assumptions, write_contrast_report

        write_contrast_report(content, dict(per_case), out, label or result.summary.model,
                              assumptions(result.summary, scenario, content["material"]))
    return Contrast(content, per_case)


def observe(result: Result | str | Path, tle, site, start, end, *, step_s: float = 10.0, satellite: str | None = None, target=None,
            camera=None, draws: int = 200, seed: int = 0, p_false_alarm: float = 1e-3, band_um=(1.5, 1.8), out=None,
            progress: bool = False, exposures_per_step: int = 1, sky_magnitude_zenith: float = 5.40, p_max: float = 0.7):
    """A pass of the satellite of ``tle`` (a TLE file; ``satellite`` picks one of several) over ``site`` ((lat_deg,
    lon_deg[, height_m]) or "LAT,LON[,HEIGHT_M]") from ``start`` to ``end`` (ISO 8601 with offset) every ``step_s``
    seconds, its faces (``target``: a TOML file of [[faces]] or a list of ``orbit.Face``; default a 1 m cube with a
    4 m^2 sun-tracking panel) made of the material of ``result`` (a Result, or its run folder, read after every
    other argument is checked; ``draws`` posterior draws, n and k at the band's centre for a run over several
    wavelengths), seen by ``camera`` (a TOML file's [camera], a ``camera.sensor.Camera``, or the default),
    ``exposures_per_step`` exposures averaged at each time, under a sky of ``sky_magnitude_zenith`` mag arcsec^-2 at
    the zenith (CIE clear-sky pattern) polarized up to ``p_max`` (Rayleigh). Returns the ``detect.observation.Observation``:
    P_d(t) per detector (intensity and Stokes matched filters, the DoLP image) at ``p_false_alarm``, P_d over the
    whole pass, light curves with their posterior bands; with ``out`` observe.json, light_curves.png and
    report.html."""
    from ..detect.observation import observe_result

    if out is not None:
        from ..io.output import check_output_dir

        out = check_output_dir(Path(out))
    site = parse_site(site)
    if not (isinstance(draws, int) and draws >= 1):
        raise ParameterError(f"--draws {draws}: need a whole number of at least 1")
    if not (isinstance(exposures_per_step, int) and exposures_per_step >= 1):
        raise ParameterError(f"--exposures {exposures_per_step}: need a whole number of at least 1")
    sky_magnitude_zenith = finite_number("sky-zenith-mag", sky_magnitude_zenith)
    if not 0 <= finite_number("p-max", p_max) <= 1:
        raise ParameterError(f"--p-max {p_max:g}: a degree of polarization, within [0, 1]")
    if not 0 < p_false_alarm < 0.5:
        raise ParameterError(f"--p-false-alarm {p_false_alarm:g}: need a probability in (0, 0.5)")
    from ..orbit.pass_geometry import time_steps

    time_steps(start, end, step_s)  # the window, checked before the run is read
    if not isinstance(result, Result):  # a run folder
        result = Result.load(result)
    observation, assumptions = observe_result(result, tle, site, start, end, step_s=step_s, satellite=satellite,
                                              target=target, camera=camera, draws=draws, rng=np.random.default_rng(seed),
                                              p_false_alarm=p_false_alarm, band_um=band_um, progress=progress,
                                              exposures_per_step=exposures_per_step,
                                              sky_magnitude_zenith=sky_magnitude_zenith, p_max=p_max)
    if out is not None:
        from ..report.observe_report import write_observe_report

        write_observe_report(observation, out, assumptions)
    return observation


def frame(path, method: str = "superpixel", out=None):
    """A raw micro-polarizer frame (an 8- or 16-bit single-channel image of the IMX250MZR mosaic) as Stokes, DoLP
    and AoP maps (``camera.mosaic.StokesMaps``): ``method`` "superpixel" (half resolution, no interpolation) or
    "bilinear" (full resolution, polanalyser's interpolation). With ``out``: frame.png, stokes.npz, frame.json."""
    from ..camera.mosaic import stokes_maps

    if method not in ("superpixel", "bilinear"):
        raise ParameterError(f"--method {method}: superpixel or bilinear")
    if out is not None:
        from ..io.output import check_output_dir

        out = check_output_dir(Path(out))
    maps = stokes_maps(Path(path), method=method)
    if out is not None:
        from ..report.frame_report import write_frame_report

        write_frame_report(maps, out)
    return maps


@dataclass
class Sky:
    """The sun and the sky's polarization at a site and time: ``content`` is sky.json's record (sun, site, model,
    DOP and AoP at each direction, neutral points, projections); ``model`` the sky model, ``sun`` its position."""

    content: dict
    model: object
    sun: object

    @property
    def directions(self) -> list[dict]:
        """DOP and AoP (deg) at each direction asked for."""
        return self.content["directions"]

    def to_json(self) -> dict:
        """sky.json's content."""
        return self.content


def sky(lat_deg, lon_deg, time: str, directions=(), *, model: str = "rayleigh", p_max: float | None = None,
        delta_deg: float = 20.0, out=None) -> Sky:
    """The sun (astropy) and the sky's DOP and AoP at a site (degrees, north and east positive) and an ISO 8601 time
    with its UTC offset. ``directions``: (zenith, azimuth) pairs or ``"ZENITH,AZIMUTH"`` text in degrees, azimuth
    east of north; ``model``: ``rayleigh`` (P_max default 1) or ``berry-dennis-lee`` (P_max default 0.8, neutral
    points ``delta_deg`` from the sun). With ``out`` the maps and sky.json are written there."""
    from ..skylight.neutral_points import BerryDennisLeeSky
    from ..skylight.projections import PROJECTIONS, cap_fraction
    from ..skylight.rayleigh import RayleighSky
    from ..skylight.sun import sun_position

    lat, lon = finite_number("lat", lat_deg), finite_number("lon", lon_deg)
    if p_max is not None:
        p_max = finite_number("p-max", p_max, 0.0)
    delta_deg = finite_number("delta-deg", delta_deg, 0.0)
    if model not in ("rayleigh", "berry-dennis-lee"):
        raise UnknownNameError(f"unknown sky model '{model}' (known: rayleigh, berry-dennis-lee)")
    pairs = [parse_direction(d) for d in directions]
    sky_model = (RayleighSky(1.0 if p_max is None else p_max) if model == "rayleigh"
                 else BerryDennisLeeSky(0.8 if p_max is None else p_max, delta_deg))
    sun = sun_position(lat, lon, time)
    s = (sun.zenith_deg, sun.azimuth_deg)
    content = {
        "sun": {"zenith_deg": sun.zenith_deg, "azimuth_deg": sun.azimuth_deg, "altitude_deg": sun.altitude_deg,
                "time_utc": sun.time_utc, "azimuth_convention": "degrees east of north", "refraction": "none"},
        "site": {"lat_deg": lat, "lon_deg": lon, "time": time},
        "model": {"name": sky_model.name, "p_max": sky_model.p_max}
                 | ({"delta_deg": sky_model.delta_deg} if model != "rayleigh" else {}),
        "aop_frame": "angle of the E-vector from the local meridian (towards the zenith), positive towards increasing azimuth",
        "sun_below_horizon": bool(sun.zenith_deg > 90),
        "directions": [{"zenith_deg": z, "azimuth_deg": a, "dop": float(sky_model.dop(z, a, s)),
                        "aop_deg": float(sky_model.aop(z, a, s))} for z, a in pairs],
        "projections": {name: {"zenith_30_cap_share_of_map": cap_fraction(p, 30.0),
                               "max_angular_distortion_deg": float(p.tissot(89.999)["angular_distortion_deg"]),
                               "areal_scale_at_horizon": float(p.tissot(89.999)["areal_scale"])}
                        for name, p in PROJECTIONS.items()},
    }
    points = {f"target {i + 1}": d for i, d in enumerate(pairs)}
    if model != "rayleigh":
        content["neutral_points"] = {k: {"zenith_deg": z, "azimuth_deg": a} for k, (z, a) in sky_model.neutral_points(s).items()}
        points.update(sky_model.neutral_points(s))
    if out is not None:
        from ..io.atomic import save_figure, write_json
        from ..io.output import check_output_dir
        from ..report.sky_figures import projection_distortion_figure, sky_maps_figure

        out = check_output_dir(Path(out))
        out.mkdir(parents=True, exist_ok=True)
        save_figure(sky_maps_figure(sky_model, s, points), out / "sky_maps.png")
        save_figure(projection_distortion_figure(), out / "projections.png")
        write_json(out / "sky.json", content)
    return Sky(content, sky_model, sun)
