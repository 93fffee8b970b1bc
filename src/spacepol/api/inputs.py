"""What the user hands the API, read and checked: data files, wavelengths, models, observables, priors, parameter
values, sites and directions; a wrong value is one line naming the option it came from."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ParameterError, SpacepolError
from ..io.dataset import Dataset
from ..physics.model import Model


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
    from ..io.measurements import read_measurements

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


def as_dataset(data, wavelength_um=None, in_plane: bool = False) -> Dataset:
    """``data`` as a Dataset: a Dataset as it is, a file path through ``load``."""
    return load(data, wavelength_um, in_plane) if isinstance(data, (str, Path)) else data


def build_model(spec, data: Dataset | None = None, dispersion: dict | str | None = None):
    """The model named by ``spec`` (an effect list such as ``"paper+lambertian"``, a preset, or a Model). Over the
    several wavelengths of ``data`` a SpectralModel: n, k per wavelength, or the ``dispersion`` law
    ({"n": "cauchy"} or ``"n=cauchy"``)."""
    from ..physics.spectral import SpectralModel

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
    from ..observables import registry

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
    from ..infer.posterior import Posterior

    where = str(prior) if isinstance(prior, (str, Path)) else "priors"
    return Posterior.build(data, build_model(model, data, dispersion), prior_overrides(prior),
                           observables=parse_observables(observables), robust=robust, where=where)


def prior_overrides(prior) -> dict | None:
    """{parameter: Prior} of a prior TOML file, or the mapping given (None: the model's own priors)."""
    if isinstance(prior, (str, Path)):
        from ..infer.prior_set import read_prior_file

        return read_prior_file(prior)
    return None if prior is None else dict(prior)


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


def parse_site(value) -> tuple[float, float, float]:
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


def parse_direction(value) -> tuple[float, float]:
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


def finite_number(name: str, value, low: float | None = None) -> float:
    """``value`` as a finite float (at least ``low`` when given); else one line naming ``name``."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"--{name} '{value}': not a number") from None
    if not np.isfinite(number):
        raise ParameterError(f"--{name} {value}: '{value}' is not a finite number")
    if low is not None and number < low:
        raise ParameterError(f"--{name} {number:g}: must be >= {low:g}")
    return number


def name_values(items, flag: str) -> list[tuple[str, str]]:
    """``["n=1.5", ...]`` as (name, text) pairs; an item without a name or '=' is one line naming ``flag``."""
    pairs = []
    for item in items:
        name, sep, text = item.partition("=")
        if not sep or not name.strip():
            raise ParameterError(f"{flag} '{item}': expected NAME=VALUE")
        pairs.append((name.strip(), text))
    return pairs


def _number_of(flag: str, name: str, text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise ParameterError(f"{flag} '{name}={text}': '{text}' is not a number") from None


def parse_settings(items, model) -> dict[str, float]:
    """``--set`` texts (``["n=1.5", "k=0"]``) -> {"n": 1.5, "k": 0.0}, each name and value checked against
    ``model`` (``parameter_values``)."""
    values = {}
    for name, text in name_values(items, "--set"):
        values[name] = _number_of("--set", name, text)
        parameter_values(model, {name: values[name]}, where="--set")
    return values


def parse_references(items) -> dict[str, float]:
    """``--reference`` texts (``["n=1.35"]``) -> {"n": 1.35}; the run checks the names against the model."""
    return {name: _number_of("--reference", name, text) for name, text in name_values(items, "--reference")}


def parse_engine_options(items) -> dict:
    """``--engine-option`` texts (``["replicates=5", "live=300"]``) -> {"replicates": 5, "live": 300}: whole numbers
    as int, other numbers as float, true/false as bool, the rest as text; the engine checks the names."""
    options = {}
    for name, text in name_values(items, "--engine-option"):
        value: object = text
        for convert in (int, float):
            try:
                value = convert(text)
                break
            except ValueError:
                continue
        if text.lower() in ("true", "false"):
            value = text.lower() == "true"
        options[name] = value
    return options
