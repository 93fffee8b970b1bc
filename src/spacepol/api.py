"""spacepol from Python: every command of ``invert-mcmc`` is a call here first.

    import spacepol
    data = spacepol.load("data/ptfe/ptfe_mueller_brdf.csv", wavelength_um=0.633, in_plane=True)
    result = spacepol.invert(data, "paper", seed=0, out="runs/ptfe")   # a Result
    again = spacepol.Result.load("runs/ptfe")
    table3 = spacepol.contrast(again)                                  # a Contrast

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import ParameterError, SpacepolError, UnknownNameError
from .infer.result import Result
from .io.dataset import Dataset
from .physics.model import Model



def parse_wavelengths(text: str):
    """``"0.633"`` -> 0.633; ``"0.532,0.633"`` -> [0.532, 0.633]; ``"all"`` -> "all". Each value a finite number > 0."""
    import math

    if text.strip().lower() == "all":
        return "all"
    values = []
    for item in text.split(","):
        try:
            value = float(item.strip())
        except ValueError:
            raise ParameterError(f"'{item.strip()}' is not a number") from None
        if not math.isfinite(value):
            raise ParameterError(f"'{item.strip()}' is not a finite number")
        if value <= 0:
            raise ParameterError(f"{value:g}: must be > 0")
        values.append(value)
    return values[0] if len(values) == 1 else values


def load(path, wavelength_um=None, in_plane: bool = False) -> Dataset:
    """The measurements of a CSV or NIST file. A file over several wavelengths needs ``wavelength_um``: one value,
    a list, ``"all"``, or text as the command line takes it (``"0.532,0.633"``); ``in_plane`` keeps the rows in the
    plane of incidence."""
    from .io.measurements import read_measurements

    if isinstance(wavelength_um, str):
        wavelength_um = parse_wavelengths(wavelength_um)
    data = read_measurements(path)
    if data.wavelength_um is not None and len(np.unique(data.wavelength_um)) > 1 and wavelength_um is None:
        have = ", ".join(f"{w:g}" for w in np.unique(data.wavelength_um))
        raise SpacepolError(f"{path}: holds several wavelengths ({have} um); choose one with --wavelength-um, "
                            f"a comma list, or all")
    if isinstance(wavelength_um, (list, tuple)):
        data = data.at_wavelengths([float(w) for w in wavelength_um])
    elif wavelength_um == "all":
        if data.wavelength_um is None:
            raise SpacepolError(f"{path}: --wavelength-um all, but the file gives no wavelength")
    elif wavelength_um is not None:
        data = data.at_wavelength(float(wavelength_um))
    return data.in_plane() if in_plane else data


def build_model(spec, data: Dataset | None = None, dispersion: dict | str | None = None):
    """The model named by ``spec`` (an effect list such as ``"paper+lambertian"``, a preset, or a Model). Over the
    several wavelengths of ``data`` a SpectralModel: n, k per wavelength, or the ``dispersion`` law
    ({"n": "cauchy"} or ``"n=cauchy"``)."""
    from .physics.spectral import SpectralModel

    if isinstance(spec, SpectralModel):
        return spec
    base = spec if isinstance(spec, Model) else Model.from_string(spec)
    laws = _dispersion(dispersion)
    wavelengths = np.unique(data.wavelength_um) if data is not None and data.wavelength_um is not None else []
    if len(wavelengths) > 1:
        return SpectralModel(base, wavelengths, laws)
    if laws:
        raise ParameterError(f"--dispersion {dispersion}: needs several wavelengths (--wavelength-um all or a list)")
    return base


def _dispersion(value) -> dict:
    if not value:
        return {}
    if isinstance(value, dict):
        return dict(value)
    name, sep, law = str(value).partition("=")
    if not sep or not law:
        raise ParameterError(f"--dispersion '{value}': write NAME=LAW, e.g. n=cauchy")
    return {name.strip(): law.strip()}


def parse_observables(names) -> list[str] | None:
    """``"dop,brdf"`` or ``["dop", "brdf"]`` checked against the observable registry (a user's observable as
    ``path/to/file.py:Name``, registered here); None keeps what the data hold."""
    if names is None:
        return None
    from .observables import registry

    text = names if isinstance(names, str) else ",".join(names)
    names = [o.strip() for o in text.split(",")]
    for name in names:
        if not name:
            raise ParameterError(f"--observables '{text}': an empty name (use e.g. dop,brdf)")
        if names.count(name) > 1:
            raise ParameterError(f"--observables '{text}': '{name}' named twice (each observable counts once)")
    chosen = []
    for name in names:
        try:
            observable = registry.get(name)
        except SpacepolError as exc:
            raise ParameterError(f"--observables '{text}': {exc}") from None
        chosen.append(observable.name if ".py:" in name else name)  # a file's observable by its registered name
    return chosen


def build_posterior(data: Dataset, model="paper", prior=None, observables=None, dispersion=None, robust: bool = False):
    """The Posterior (likelihood and priors) of a model on a data set. ``prior``: a prior TOML file or
    {parameter: Prior}; ``observables``: which observables to fit (default: all the data hold)."""
    from .infer.posterior import Posterior

    where = str(prior) if isinstance(prior, (str, Path)) else "priors"
    return Posterior.build(data, build_model(model, data, dispersion), _prior_overrides(prior),
                           observables=parse_observables(observables), robust=robust, where=where)


def _prior_overrides(prior) -> dict | None:
    """{parameter: Prior} of a prior TOML file, or the mapping given (None: the model's own priors)."""
    if isinstance(prior, (str, Path)):
        from .infer.prior_set import read_prior_file

        return read_prior_file(prior)
    return None if prior is None else dict(prior)


def invert(data, model="paper", prior=None, engine: str = "emcee", seed: int = 0, out=None, *,
           observables=None, dispersion=None, walkers: int | None = None, steps: int | None = None,
           robust: bool = False, restart: bool = False, progress: bool = False, references: dict | None = None,
           engine_options: dict | None = None) -> Result:
    """Sample the posterior of ``model`` (an effect list, a preset or a Model) on ``data`` (a Dataset or a file path) and return its Result.

    ``engine``: a sampler of the engine registry: ``emcee`` (affine-invariant ensemble, the default), ``laplace`` (a
    Laplace approximation at the optimum corrected by importance sampling; emcee where its checks refuse it, and the
    summary says so: ``engine`` and ``laplace_refused``), ``nuts``, an entry point of group ``spacepol.engines`` or a
    file ``path/to/engine.py:Name``.
    ``walkers`` and ``steps`` are emcee's (``walkers``, ``max_steps``); ``engine_options`` go to the engine's ``run``.
    With ``out`` the run is kept in that folder as ``invert-mcmc run`` keeps it: for a resumable engine (emcee) the
    chain (an interrupted call continues with the same arguments; ``restart`` starts afresh and keeps the old chain
    aside), posterior.nc, summary.json, figures and report.html. ``references``: {parameter: value} to compare the
    posterior with (e.g. a known index)."""
    from .infer.engine_registry import SAMPLER, engines

    sampler = engines.get(engine, SAMPLER)
    options = {**({"walkers": walkers} if walkers is not None else {}),
               **({"max_steps": steps} if steps is not None else {}), **(engine_options or {})}
    sampler.check_options(options)
    parse_observables(observables)  # registers a user's observable file before its columns are read
    data = load(data) if isinstance(data, (str, Path)) else data
    post = build_posterior(data, model, prior, observables, dispersion, robust)
    if walkers is not None:
        from .infer.inversion import check_walkers

        check_walkers(walkers, post.ndim)
    if references:
        for name, value in references.items():
            if name not in post.names:
                raise ParameterError(f"--reference '{name}={value:g}': '{name}' is not a free parameter "
                                     f"({', '.join(post.names)})")
    if out is None:
        return sampler.result(post, seed=seed, progress=progress, **options)
    return _invert_into(Path(out), post, sampler, seed, options, restart, progress, references)


def _invert_into(out: Path, post, sampler, seed, options, restart, progress, references) -> Result:
    from .infer.chain_file import set_aside
    from .io.output import check_output_dir, folder_lock
    from .report.run_report import write_run_report

    check_output_dir(out)
    made_folder = not out.exists()
    chain = out / "chain.h5" if sampler.resumable else None
    fresh = chain is None or not chain.exists()
    with folder_lock(out):  # first: a second run on this folder stops here, before it reads the chain
        try:
            if chain is not None and not restart:
                sampler.check_chain(chain, post, seed, **options)
            if progress:
                lik = post.likelihood
                print(f"sampling {', '.join(post.names)} from {len(lik.data)} geometries ({', '.join(lik.observables)}), "
                      f"model {lik.model.name}", file=sys.stderr)
                if lik.left_out:
                    print(f"  not fitted: {', '.join(lik.left_out)} ({' and '.join(sorted(set(lik.left_out.values())))} "
                          f"holds their numbers; --observables chooses)", file=sys.stderr)
            if restart and chain is not None and (old := set_aside(chain)) is not None and progress:
                print(f"  --restart: the previous chain is kept as {old}", file=sys.stderr)
            result = sampler.result(post, seed=seed, progress=progress, chain=chain, **options)
        except KeyboardInterrupt:
            raise  # the chain so far is kept: the same call continues it
        except BaseException:
            _discard_unstarted(chain, out, fresh or restart, made_folder)
            raise
        if progress:
            print("  writing the report (figures, posterior.nc, summary.json, report.html)", file=sys.stderr)
        write_run_report(result, out, _data_label(post.likelihood.data), references=references)
    return result


def _data_label(data: Dataset) -> str:
    return data.source or "data"


def _discard_unstarted(chain: Path | None, out: Path, fresh: bool, made_folder: bool) -> None:
    """A run that failed before its first stored step leaves nothing behind that would block the
    corrected call (a chain stamped with the failed run's settings would)."""
    from .infer.chain_file import ChainFileError, chain_iterations

    if chain is not None:
        try:
            empty = fresh and chain.exists() and chain_iterations(chain) == 0
        except ChainFileError:
            empty = fresh
        if empty:
            chain.unlink(missing_ok=True)
    if made_folder and out.is_dir() and not any(p.name != ".spacepol.lock" for p in out.iterdir()):
        import shutil

        shutil.rmtree(out, ignore_errors=True)


def parameter_values(model, values: dict | None, where: str = "--set") -> dict[str, float]:
    """``values`` checked against the model's parameters (names and physical bounds) and completed with the
    model's defaults."""
    model = build_model(model)
    checked = {}
    for name, value in (values or {}).items():
        param = model.parameter(name)
        param.check(float(value), where=where)
        checked[name] = float(value)
    return {**model.defaults(), **checked}


def forward(model, geometry, values: dict | None = None):
    """The model's Prediction (Stokes vector, DOP, AoP, BRDF, Mueller matrix) at ``geometry`` (a Geometry, a
    Dataset or a file of geometries) for parameter ``values`` (defaults for the rest). Non-finite or overflowing
    output is an error naming the values."""
    from .physics.geometry import Geometry

    model = build_model(model)
    if isinstance(geometry, (str, Path)):
        from .io.measurements import read_measurements

        geometry = read_measurements(geometry, require_observable=False)
    geometry = geometry.geometry if isinstance(geometry, Dataset) else geometry
    if not isinstance(geometry, Geometry):
        raise ParameterError("forward: geometry must be a Geometry, a Dataset or a file of geometries")
    full = parameter_values(model, values)
    return model.check_plugins(full, geometry).require_finite(values or {}, model.name)


def synth(model, values: dict | None = None, geometry=None, *, noise_dop: float = 0.0, noise_brdf: float | None = None,
          wavelength_um: float | None = None, seed: int = 0, out=None) -> Dataset:
    """A synthetic data set: the model's DOP at ``geometry`` (a Geometry, a Dataset, a file, or the paper's default
    grid) with Gaussian noise ``noise_dop`` (absolute, clipped to [0, 1]) and, when ``noise_brdf`` is given, the
    BRDF with that relative noise. The truth is in ``metadata`` (``truth_NAME``); ``out`` writes it as a CSV."""
    from .io.measurements import read_measurements, write_table
    from .physics.geometry import Geometry, default_grid

    model = build_model(model)
    full = parameter_values(model, values)
    if noise_dop < 0 or (noise_brdf is not None and noise_brdf < 0):
        raise ParameterError("noise levels must be >= 0")
    if isinstance(geometry, (str, Path)):
        geometry = read_measurements(geometry, require_observable=False)
    geometry = default_grid() if geometry is None else geometry.geometry if isinstance(geometry, Dataset) else geometry
    wavelength = geometry.wavelength_um
    if wavelength_um is not None:
        wavelength = np.full(geometry.size, float(wavelength_um))
        geometry = Geometry(geometry.theta_i, geometry.theta_r, geometry.dphi, wavelength)
    rng = np.random.default_rng(seed)
    prediction = model.check_plugins(full, geometry).require_finite(values or {}, model.name)
    columns = {"theta_i": geometry.theta_i, "theta_r": geometry.theta_r, "dphi": geometry.dphi,
               "dop": np.clip(prediction.dop + rng.normal(0.0, noise_dop, geometry.size), 0.0, 1.0)}
    if noise_dop > 0:
        columns["dop_err"] = np.full(geometry.size, noise_dop)
    if noise_brdf is not None:
        columns["brdf"] = np.maximum(prediction.brdf * (1.0 + rng.normal(0.0, noise_brdf, geometry.size)), 0.0)
        if noise_brdf > 0:
            columns["brdf_err"] = noise_brdf * prediction.brdf
    if wavelength is not None:
        columns["wavelength_um"] = np.asarray(wavelength, float)
    meta = {"source": "spacepol synth", "model": model.name, "seed": seed, "noise_dop": noise_dop,
            **{f"truth_{k}": v for k, v in full.items()}}
    if out is not None:
        write_table(out, columns, meta)
    return Dataset(**{k: np.asarray(v, float) for k, v in columns.items()}, metadata=meta,
                   source=str(out) if out is not None else "spacepol synth")


def calibrate(model, priors: dict, geometry, *, engine="emcee", replicates: int = 100, seed: int = 0,
              engine_options: dict | None = None, noise_dop: float = 0.01, noise_brdf: float = 0.05,
              mueller_noise: float | None = None, likelihood_noise_scale: float = 1.0, progress: bool = False):
    """Simulation-based calibration of a sampling ``engine`` (a registry name or an ``Engine``;
    ``infer.calibration``): ``replicates`` truths from ``priors`` ({name: Prior}; the model's defaults for the rest),
    data simulated at ``geometry`` (a Geometry, a Dataset or a file of geometries) with Gaussian noise of known size,
    one run each. Returns a ``Calibration``:
    coverage of the 50 % and 90 % intervals, rank histograms and their figure, ``calibrated``, ``failures``."""
    from .infer.calibration import calibrate as run_sbc
    from .io.measurements import read_measurements

    if replicates < 1:
        raise ParameterError(f"replicates {replicates}: need at least 1")
    if isinstance(geometry, (str, Path)):
        geometry = read_measurements(geometry, require_observable=False)
    geometry = geometry.geometry if isinstance(geometry, Dataset) else geometry
    return run_sbc(engine, build_model(model), priors, geometry, replicates, np.random.default_rng(seed),
                   engine_options=engine_options, noise_dop=noise_dop, noise_brdf=noise_brdf,
                   mueller_noise=mueller_noise, likelihood_noise_scale=likelihood_noise_scale, progress=progress)


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


def contrast(result: Result, scenario=None, out=None, *, reading: str = "corrected", draws: int = 20000, seed: int = 0,
             extrapolate: bool = False) -> Contrast:
    """Propagate a Result's posterior into target DOP, sky DOP, limiting magnitude and contrasts in ``scenario``
    (a TOML path, a dict laid out as that file, or a Scenario; default the paper's Table 3). Over several wavelengths n and k at the scenario's
    wavelength come from the Result's own model (dispersion law or interpolation; beyond the measured range only
    with ``extrapolate``). With ``out`` the files of ``invert-mcmc contrast`` are written there."""
    from .detect.contrast import contrast_of
    from .detect.scenario import default_scenario, read_scenario, scenario_from_dict

    if scenario is None:
        scenario = default_scenario()
    elif isinstance(scenario, (str, Path)):
        scenario = read_scenario(scenario)
    elif isinstance(scenario, dict):
        scenario = scenario_from_dict(scenario)
    if out is not None:
        from .io.output import check_output_dir

        out = check_output_dir(Path(out))  # before the work
    content, per_case = contrast_of(result, scenario, seed, draws, reading, extrapolate)
    if out is not None:
        from .report.contrast_report import assumptions, write_contrast_report

        write_contrast_report(content, dict(per_case), out, result.summary["model"],
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
    from .detect.observation import observe_result

    if out is not None:
        from .io.output import check_output_dir

        out = check_output_dir(Path(out))
    site = _site(site)
    if not (isinstance(draws, int) and draws >= 1):
        raise ParameterError(f"--draws {draws}: need a whole number of at least 1")
    if not (isinstance(exposures_per_step, int) and exposures_per_step >= 1):
        raise ParameterError(f"--exposures {exposures_per_step}: need a whole number of at least 1")
    sky_magnitude_zenith = _finite_number("sky-zenith-mag", sky_magnitude_zenith)
    if not 0 <= _finite_number("p-max", p_max) <= 1:
        raise ParameterError(f"--p-max {p_max:g}: a degree of polarization, within [0, 1]")
    if not 0 < p_false_alarm < 0.5:
        raise ParameterError(f"--p-false-alarm {p_false_alarm:g}: need a probability in (0, 0.5)")
    from .orbit.pass_geometry import time_steps

    time_steps(start, end, step_s)  # the window, checked before the run is read
    if not isinstance(result, Result):  # a run folder
        result = Result.load(result)
    observation, assumptions = observe_result(result, tle, site, start, end, step_s=step_s, satellite=satellite,
                                              target=target, camera=camera, draws=draws, rng=np.random.default_rng(seed),
                                              p_false_alarm=p_false_alarm, band_um=band_um, progress=progress,
                                              exposures_per_step=exposures_per_step,
                                              sky_magnitude_zenith=sky_magnitude_zenith, p_max=p_max)
    if out is not None:
        from .report.observe_report import write_observe_report

        write_observe_report(observation, out, assumptions)
    return observation


def frame(path, method: str = "superpixel", out=None):
    """A raw micro-polarizer frame (an 8- or 16-bit single-channel image of the IMX250MZR mosaic) as Stokes, DoLP
    and AoP maps (``camera.mosaic.StokesMaps``): ``method`` "superpixel" (half resolution, no interpolation) or
    "bilinear" (full resolution, polanalyser's interpolation). With ``out``: frame.png, stokes.npz, frame.json."""
    from .camera.mosaic import stokes_maps

    if method not in ("superpixel", "bilinear"):
        raise ParameterError(f"--method {method}: superpixel or bilinear")
    if out is not None:
        from .io.output import check_output_dir

        out = check_output_dir(Path(out))
    maps = stokes_maps(Path(path), method=method)
    if out is not None:
        from .report.frame_report import write_frame_report

        write_frame_report(maps, out)
    return maps


def _site(value) -> tuple[float, float, float]:
    """A site as "LAT,LON[,HEIGHT_M]" text or a tuple, checked."""
    text = value if isinstance(value, str) else ",".join(str(v) for v in value)
    try:
        numbers = [float(v) for v in text.split(",")]
    except ValueError:
        raise ParameterError(f"--site '{text}': expected LAT,LON[,HEIGHT_M] in degrees and metres") from None
    if len(numbers) not in (2, 3) or not all(np.isfinite(numbers)):
        raise ParameterError(f"--site '{text}': expected LAT,LON[,HEIGHT_M] in degrees and metres")
    lat, lon, height = (numbers + [0.0])[:3]
    if not (-90 <= lat <= 90 and -180 <= lon <= 360):
        raise ParameterError(f"--site '{text}': latitude in [-90, 90], longitude in [-180, 360] deg")
    return lat, lon, height


def _direction(value) -> tuple[float, float]:
    """A direction as ``"ZENITH,AZIMUTH"`` text or a pair, in degrees, checked."""
    text = value if isinstance(value, str) else ",".join(str(v) for v in value)
    try:
        zen, az = (float(v) for v in text.split(","))
    except ValueError:
        raise ParameterError(f"--direction '{text}': expected ZENITH,AZIMUTH in degrees, e.g. 60,101.5") from None
    if not 0 <= zen <= 90:
        raise ParameterError(f"--direction '{text}': zenith angle must lie in [0, 90] deg")
    if not np.isfinite(az):
        raise ParameterError(f"--direction '{text}': azimuth {az:g} deg is not a finite number")
    return zen, az


def _finite_number(name: str, value, low: float | None = None) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"--{name} '{value}': not a number") from None
    if not np.isfinite(number):
        raise ParameterError(f"--{name} {value}: '{value}' is not a finite number")
    if low is not None and number < low:
        raise ParameterError(f"--{name} {number:g}: must be >= {low:g}")
    return number


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
    from .skylight.neutral_points import BerryDennisLeeSky
    from .skylight.projections import PROJECTIONS, cap_fraction
    from .skylight.rayleigh import RayleighSky
    from .skylight.sun import sun_position

    lat, lon = _finite_number("lat", lat_deg), _finite_number("lon", lon_deg)
    if p_max is not None:
        p_max = _finite_number("p-max", p_max, 0.0)
    delta_deg = _finite_number("delta-deg", delta_deg, 0.0)
    if model not in ("rayleigh", "berry-dennis-lee"):
        raise UnknownNameError(f"unknown sky model '{model}' (known: rayleigh, berry-dennis-lee)")
    pairs = [_direction(d) for d in directions]
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
        from .io.atomic import save_figure, write_json
        from .io.output import check_output_dir
        from .report.sky_figures import projection_distortion_figure, sky_maps_figure

        out = check_output_dir(Path(out))
        out.mkdir(parents=True, exist_ok=True)
        save_figure(sky_maps_figure(sky_model, s, points), out / "sky_maps.png")
        save_figure(projection_distortion_figure(), out / "projections.png")
        write_json(out / "sky.json", content)
    return Sky(content, sky_model, sun)


@dataclass
class Diagnosis:
    """What ``diagnose`` found: ``content`` is the JSON record (verdict, conclusion, ranking of every candidate
    change with delta ELPD-LOO and its standard error, how each refit's posterior was obtained; with rounds the
    path), ``base`` the Result of the starting model, ``confirmed`` the refitted candidates, ``rungs`` the path of
    ``rounds`` as ladder rungs (None without rounds)."""

    content: dict
    base: Result
    confirmed: list
    rungs: list | None

    @property
    def verdict(self) -> str:
        """The change the data support most, or that none does, in words."""
        return self.content["verdict"]

    @property
    def ranking(self) -> list[dict]:
        """Every candidate change, best first."""
        return self.content["ranking"]

    def to_json(self) -> dict:
        """The JSON record ``diagnose --json`` writes."""
        return self.content


def diagnose(data, model="paper", *, rounds: int | None = None, candidates=None, top: int = 3, prior=None,
             observables=None, dispersion=None, posterior: str = "laplace", seed: int = 0, out=None,
             json_path=None, wavelength_um=None, in_plane: bool = False, workers: int = 1,
             criterion: str = "loo") -> Diagnosis:
    """Which physical effect is missing or wrong: every candidate change (add, remove or replace an effect) is
    screened and the ``top`` ones refitted and compared by PSIS-LOO. ``rounds``: apply the best change and diagnose
    again, up to that many times. ``posterior``: ``laplace`` (importance-corrected, emcee where it cannot be
    trusted) or ``emcee`` for every refit. With ``out`` the figures and report.html are written there, with
    ``json_path`` the JSON record. ``data``: a Dataset, or a file read (after every other argument is checked) with
    ``wavelength_um`` and ``in_plane`` as ``load`` reads it. ``workers``: candidates searched and refitted at once,
    each in its own process (the answer does not depend on it). ``criterion``: ``loo`` (delta ELPD-LOO) or
    ``evidence`` (ln Bayes factor) ranks the refitted changes; each entry holds both where both are known."""
    from .criticism.diagnose import CRITERIA
    from .criticism.diagnose import diagnose as run_diagnose
    from .io.output import check_output_dir, check_output_file
    from .physics.registry import registry

    if json_path is not None:
        check_output_file(json_path, "--json")
    if out is not None:
        check_output_dir(out)
    build_model(model)  # a wrong name fails before the data are read
    overrides = _prior_overrides(prior)
    for name in candidates or []:
        registry.get(name)
    if top < 1:
        raise ParameterError(f"--top {top}: need at least 1")
    if posterior not in ("laplace", "emcee"):
        raise UnknownNameError(f"--posterior {posterior}: unknown (laplace, emcee)")
    if criterion not in CRITERIA:
        raise UnknownNameError(f"--criterion {criterion}: unknown ({', '.join(CRITERIA)})")
    if not isinstance(workers, int) or workers < 1:
        raise ParameterError(f"--workers {workers}: need a whole number of at least 1")
    data = load(data, wavelength_um, in_plane) if isinstance(data, (str, Path)) else data
    full_model = build_model(model, data, dispersion)  # over several wavelengths: n, k per wavelength
    fitted = parse_observables(observables)
    rng = np.random.default_rng(seed)
    if rounds:
        from .criticism.rounds import as_rungs, diagnose_rounds

        content = diagnose_rounds(data, full_model, rng, rounds, seed=seed, observables=fitted, candidates=candidates,
                                  top=top, priors=overrides, posterior_method=posterior, workers=workers, criterion=criterion)
        rungs = as_rungs(content)
        base, confirmed = content.reports[0].base, content.reports[0].confirmed
    else:
        content = run_diagnose(data, full_model, rng, seed=seed, observables=fitted, candidates=candidates, top=top,
                               priors=overrides, posterior_method=posterior, workers=workers, criterion=criterion)
        base, confirmed = content.base, content.confirmed
        rungs = None
    if out is not None:
        from .report.diagnose_report import write_diagnose_report

        write_diagnose_report(content.to_json(), base, confirmed, Path(out), _data_label(data), path_rungs=rungs)
    if json_path is not None:
        from .io.atomic import write_json

        write_json(json_path, content.to_json())
    return Diagnosis(content.to_json(), base, confirmed, rungs)


@dataclass
class Ladder:
    """The rungs of a ladder: one per model, from the start through each change in order, with its fit (ELPD-LOO
    and its difference to the rung below, reduced chi^2, the noise it infers) and its Result."""

    rungs: list

    def to_json(self) -> list[dict]:
        """The rungs as ``ladder.json`` holds them (without the Results)."""
        return [rung.to_json() for rung in self.rungs]


def ladder(data, model="paper", changes=(), *, observables=None, dispersion=None, seed: int = 0, out=None,
           json_path=None, wavelength_um=None, in_plane: bool = False) -> Ladder:
    """Fit the model and then each change in order (``"lambertian"``, ``"replace shadowing by smith"``,
    ``"remove body"``): the ladder shows what each change buys. The whole ladder is checked to compose before any
    fit. With ``out`` the figure, table and ladder.json (or ``json_path``) are written. ``data``: a Dataset, or a file
    read with ``wavelength_um`` and ``in_plane``."""
    from .criticism.changes import parse
    from .criticism.ladder import climb
    from .io.output import check_output_dir, check_output_file

    if out is not None:
        check_output_dir(out)
    if json_path is not None:
        check_output_file(json_path, "--json")
    steps = list(changes)
    if not steps:
        raise ParameterError("ladder: give at least one --add CHANGE or --replay DIAGNOSE.json")
    current = build_model(model if isinstance(model, (str, Model)) else model.model)
    for step in steps:  # check the whole ladder composes before fitting anything
        current = parse(current, step).model
    data = load(data, wavelength_um, in_plane) if isinstance(data, (str, Path)) else data
    rungs = climb(data, build_model(model, data, dispersion), steps, seed=seed, observables=parse_observables(observables))
    if out is not None:
        from .report.ladder_report import write_ladder_report

        write_ladder_report(rungs, Path(out), json_path)
    return Ladder(rungs)


@dataclass
class Design:
    """Which measurements would shrink the worst-measured parameter combination most: ``content`` holds the ridge
    (its parameters, direction, SD relative to the prior), the greedy picks with the SD after each, the best single
    measurement per observable and the findings in words."""

    content: dict

    @property
    def picks(self) -> list[dict]:
        """The proposed measurements, best first."""
        return self.content["picks"]

    def to_json(self) -> dict:
        """``design.json``'s content."""
        return self.content


def design(data, model="paper", *, picks: int = 3, noise: dict | None = None, prior=None, observables=None,
           seed: int = 0, out=None, progress: bool = False) -> Design:
    """The next measurements to make: at the posterior optimum of ``model`` on ``data``, the Fisher information of
    every candidate geometry and observable; ``picks`` chosen greedily. ``noise``: {observable: level} for the
    candidates, e.g. {"dop": X, "brdf": REL, "mueller": X} (default: the data's own levels; the candidates are the
    observables that declare a ``design_noise``)."""
    from .criticism.design import candidate_observables
    from .criticism.design import design as rank_measurements
    from .infer.optimum import find_optimum

    if out is not None:
        from .io.output import check_output_dir

        out = check_output_dir(out)
    noise = dict(noise or {})
    candidates = candidate_observables()
    for name, value in noise.items():
        if name not in candidates or not (np.isfinite(float(value)) and float(value) > 0):
            raise ParameterError(f"--noise '{name}={value}': expected OBSERVABLE=X with OBSERVABLE in "
                                 f"{', '.join(candidates)} and a finite X > 0")
    if picks < 1:
        raise ParameterError(f"--picks {picks}: need at least 1")
    data = load(data) if isinstance(data, (str, Path)) else data
    post = build_posterior(data, model, prior, observables)
    if progress:
        print(f"design: the optimum of {post.likelihood.model.name} on {len(data)} geometries "
              f"({', '.join(post.likelihood.observables)}), then the Fisher information of every candidate",
              file=sys.stderr)
    _, theta = find_optimum(post, np.random.default_rng(seed))
    point = {k: float(np.ravel(v)[0]) for k, v in post.priors.to_params(theta[None, :]).items()}
    content = rank_measurements(post, point, picks=picks, noise=noise)
    if out is not None:
        from .report.design_report import write_design_report

        write_design_report(content, out, _data_label(data))
    return Design(content)
