"""One model over several wavelengths: geometric parameters shared, optical constants per wavelength.

The parameters an effect marks ``spectral`` (the refractive index n, k of the surface, a film's index)
get one copy per wavelength, named ``NAME@LAMBDA`` with LAMBDA as written in the data (DESIGN.md,
"Measurement files"); every other parameter (roughness, albedos, instrument effects) is shared. A
dispersion law replaces the copies of one parameter by the law's coefficients:
``cauchy`` for n, n(lambda) = A + B / lambda^2 (lambda in um; Cauchy 1836, the transparent-region law
of glasses and polymers). The model is evaluated once per wavelength on that wavelength's rows.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..priors import Uniform
from .geometry import Geometry
from .model import Model, Prediction
from .parameter import Parameter

SPECTRAL = ("n", "k", "n_film", "n_pm")  # optical constants: they change with wavelength
DISPERSION_LAWS = ("cauchy",)


def wavelength_label(value: float) -> str:
    """A wavelength as written in data files (0.633, 1.064): the shortest exact decimal."""
    return f"{value:g}"


def cauchy_parameters() -> list[Parameter]:
    """The parameters of the Cauchy law n(lambda) = A + B / lambda^2 that replace n's per-wavelength values."""
    return [Parameter("n_cauchy_a", "", Uniform(1.0, 3.0), 1.5, "Cauchy dispersion: n at infinite wavelength",
                      physical=(0.0, np.inf)),
            Parameter("n_cauchy_b", "um^2", Uniform(-0.05, 0.1), 0.005, "Cauchy dispersion: n = A + B / lambda^2")]


class SpectralModel:
    """``model`` over ``wavelengths_um``; ``dispersion`` maps a spectral parameter to a law (``{"n": "cauchy"}``)."""

    def __init__(self, model: Model, wavelengths_um, dispersion: dict | None = None):
        self.model = model
        self.wavelengths = sorted(float(w) for w in wavelengths_um)
        self.labels = [wavelength_label(w) for w in self.wavelengths]
        self.dispersion = dict(dispersion or {})
        for name, law in self.dispersion.items():
            if law not in DISPERSION_LAWS:
                raise ParameterError(f"dispersion law '{law}' for {name}: use one of {', '.join(DISPERSION_LAWS)}")
            if name != "n":
                raise ParameterError(f"dispersion law '{law}' applies to n only, not {name}")
        own = {p.name for p in model.parameters}
        self.spectral = [n for n in SPECTRAL if n in own]
        self.shared = [n for n in own if n not in self.spectral]
        if "n" in self.dispersion and "n" not in own:
            raise ParameterError(f"--dispersion n=cauchy: model {model.name} has no n")
        self._geometries: dict = {}

    def __getstate__(self):
        # the per-geometry split is keyed by the geometry's id in this process: rebuilt where it is used
        return {**self.__dict__, "_geometries": {}}

    @property
    def name(self) -> str:
        """The inner model's name (the wavelengths are in ``wavelengths``)."""
        return self.model.name

    def __repr__(self):
        return f"SpectralModel('{self.name}' at {', '.join(self.labels)} um)"

    def with_model(self, model: Model) -> "SpectralModel":
        """Another inner model over the same wavelengths and dispersion laws (a criticism change applied)."""
        return SpectralModel(model, self.wavelengths, self.dispersion)

    def __add__(self, other):
        return self.with_model(self.model + other)

    @property
    def effects(self):
        """The inner model's effects."""
        return self.model.effects

    @property
    def parameters(self) -> list[Parameter]:
        """The shared parameters, n and k per wavelength (``n@0.633``) or the dispersion law's parameters."""
        out = []
        for p in self.model.parameters:
            if p.name not in self.spectral:
                out.append(p)
            elif self.dispersion.get(p.name) == "cauchy":
                out.extend(cauchy_parameters())
            else:
                out.extend(Parameter(f"{p.name}@{label}", p.unit, p.prior, p.default, f"{p.description} at {label} um",
                                     p.fixed, p.physical) for label in self.labels)
        return out

    def defaults(self) -> dict:
        """{parameter: default value} of every parameter."""
        return {p.name: p.default for p in self.parameters}

    def values_at(self, params: dict, j: int) -> dict:
        """The inner model's parameters at wavelength j."""
        label, lam = self.labels[j], self.wavelengths[j]
        out = {k: params[k] for k in self.shared if k in params}
        for name in self.spectral:
            if self.dispersion.get(name) == "cauchy":
                out[name] = params["n_cauchy_a"] + params["n_cauchy_b"] / lam**2
            elif f"{name}@{label}" in params:
                out[name] = params[f"{name}@{label}"]
        return out

    def derived(self, params: dict) -> dict:
        """Per-wavelength values a dispersion law implies (``n@0.633`` from A and B), for reports."""
        out = {}
        for name, law in self.dispersion.items():
            for j, label in enumerate(self.labels):
                out[f"{name}@{label}"] = self.values_at(params, j)[name]
        return out

    def values_at_wavelength(self, params: dict, wavelength_um: float, extrapolate: bool = False) -> tuple[dict, str]:
        """The inner model's parameters at any wavelength, and the rule that gave them, in words.

        Inside the measured range a dispersion law is evaluated where the run had one, and every other
        spectral parameter is interpolated linearly in wavelength between the two measured wavelengths around
        it (per posterior draw). Outside it the call fails unless ``extrapolate``: then the law is evaluated
        beyond its data, and a parameter without a law keeps its value at the nearest measured wavelength."""
        lam = float(wavelength_um)
        lo, hi = self.wavelengths[0], self.wavelengths[-1]
        outside = lam < lo * (1 - 1e-9) or lam > hi * (1 + 1e-9)
        if outside and not extrapolate:
            raise ParameterError(f"wavelength {lam:g} um lies outside the run's measured {lo:g}-{hi:g} um")
        out = {k: params[k] for k in self.shared if k in params}
        rules = []
        grid = np.array(self.wavelengths)
        for name in self.spectral:
            if self.dispersion.get(name) == "cauchy":
                out[name] = np.asarray(params["n_cauchy_a"]) + np.asarray(params["n_cauchy_b"]) / lam**2
                rules.append(f"{name} from the run's Cauchy law at {lam:g} um"
                             + (f" (extrapolated beyond {lo:g}-{hi:g} um)" if outside else ""))
                continue
            keys = [f"{name}@{label}" for label in self.labels]
            if not all(k in params for k in keys):
                continue
            values = np.stack(np.broadcast_arrays(*(np.asarray(params[k], float) for k in keys)), axis=-1)
            if outside:
                nearest = int(np.argmin(np.abs(grid - lam)))
                out[name] = values[..., nearest]
                rules.append(f"{name} held at its value at the nearest measured wavelength {self.labels[nearest]} um "
                             f"(extrapolated from {lo:g}-{hi:g} um, no dispersion law)")
                continue
            j = int(np.clip(np.searchsorted(grid, lam) - 1, 0, len(grid) - 2)) if len(grid) > 1 else 0
            if len(grid) == 1 or abs(grid[j] - lam) < 1e-9 * lam:
                out[name] = values[..., j]
                rules.append(f"{name} as measured at {self.labels[j]} um")
            elif abs(grid[j + 1] - lam) < 1e-9 * lam:
                out[name] = values[..., j + 1]
                rules.append(f"{name} as measured at {self.labels[j + 1]} um")
            else:
                w = (lam - grid[j]) / (grid[j + 1] - grid[j])
                out[name] = (1 - w) * values[..., j] + w * values[..., j + 1]
                rules.append(f"{name} interpolated linearly in wavelength between {self.labels[j]} and "
                             f"{self.labels[j + 1]} um")
        return out, "; ".join(rules)

    def _groups(self, geometry: Geometry):
        key = id(geometry)
        if key not in self._geometries:
            if geometry.wavelength_um is None:
                raise ParameterError("several wavelengths need a wavelength per measurement")
            groups = []
            for lam in self.wavelengths:
                idx = np.flatnonzero(np.abs(geometry.wavelength_um - lam) < 1e-6)
                if not idx.size:
                    groups.append((idx, None))
                    continue
                if idx[-1] - idx[0] + 1 == idx.size:
                    idx = slice(int(idx[0]), int(idx[-1]) + 1)  # a block of rows: copied, not gathered
                groups.append((idx, Geometry(geometry.theta_i[..., idx], geometry.theta_r[..., idx],
                                             geometry.dphi[..., idx], geometry.wavelength_um[idx])))
            covered = sum(sub.size for _, sub in groups if sub is not None)
            if covered != geometry.size:
                raise ParameterError(f"{geometry.size - covered} measurements lie at none of the wavelengths "
                                     f"{', '.join(self.labels)} um")
            self._geometries[key] = (geometry, groups)  # the geometry is kept so its id stays unique
        return self._geometries[key][1]

    @property
    def inner(self) -> Model:
        """The one-wavelength model the spectral model evaluates per wavelength."""
        return self.model

    def parts(self, geometry: Geometry) -> list:
        """[(rows, geometry of those rows, params -> the inner model's params)], one part per wavelength."""
        return [(idx, sub, lambda values, j=j: self.values_at(values, j))
                for j, (idx, sub) in enumerate(self._groups(geometry)) if sub is not None]

    def evaluate(self, params: dict, geometry: Geometry, mueller: bool = False, check: bool = True) -> Prediction:
        """The inner model's Prediction at each row's wavelength with that wavelength's n and k, rows in the data's
        order."""
        parts = [(idx, self.model.evaluate(self.values_at(params, j), sub, mueller=mueller, check=check))
                 for j, (idx, sub) in enumerate(self._groups(geometry)) if sub is not None]
        return _assemble(parts, geometry.size, mueller)

    def dop(self, params: dict, geometry: Geometry, check: bool = True) -> np.ndarray:
        """The measured DOP alone (``Model.dop`` per wavelength), rows in the data's order."""
        parts = [(idx, self.model.dop(self.values_at(params, j), sub, check=check))
                 for j, (idx, sub) in enumerate(self._groups(geometry)) if sub is not None]
        return _gather(parts, geometry.size, lambda dop: dop)

    def check_plugins(self, params: dict, geometry: Geometry) -> Prediction:
        """``Model.check_plugins`` per wavelength: plug-in effects' failures named, the Prediction assembled."""
        parts = [(idx, self.model.check_plugins(self.values_at(params, j), sub))
                 for j, (idx, sub) in enumerate(self._groups(geometry)) if sub is not None]
        return _assemble(parts, geometry.size, False)


def _gather(parts, size: int, get) -> np.ndarray:
    """One array over all rows (in the data's order) from ``get`` of each per-wavelength output."""
    out = np.empty(get(parts[0][1]).shape[:-1] + (size,))
    for idx, part in parts:
        out[..., idx] = get(part)
    return out


def _assemble(parts, size: int, mueller: bool) -> Prediction:
    """One Prediction over all rows from the per-wavelength ones (rows in the data's order)."""
    return Prediction.from_total(_gather(parts, size, lambda p: p.mueller if mueller else p.stokes),
                                 _gather(parts, size, lambda p: p.dop), mueller)
