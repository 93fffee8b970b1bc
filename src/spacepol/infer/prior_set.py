"""The joint prior over a model's free parameters (and the likelihood's nuisance parameters).

Defaults come from each effect's ``Parameter``; a TOML file overrides them::

    [n]                      # a parameter's table
    distribution = "uniform" # uniform | loguniform | normal (truncated to [lower, upper])
    lower = 1.0
    upper = 2.0

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..io.toml_file import read_toml
from ..physics.parameter import Parameter
from ..priors import Fixed, LogUniform, Prior, TruncatedNormal, Uniform

_KEYS = {"distribution", "lower", "upper", "mu", "sigma", "fixed"}


_NK_KEYS = {"nk_table", "wavelength_um", "relative_sigma", "sigma", "lower", "upper"}


def prior_from_nk_table(name: str, table: dict, where: str) -> Prior:
    """A truncated normal on n or k centred on a refractiveindex.info table (``data/nk/`` or a path) at the
    parameter's wavelength (``n@0.633``; or ``wavelength_um`` for a plain ``n``); width ``sigma``, or
    ``relative_sigma`` (default 5 %: tables of one material from different sources differ by that much)
    of the value, at least 1e-3; bounds 6 widths either side unless given, never below 0."""
    from ..errors import InputFileError, SpacepolError
    from ..io.nk import RefractiveIndex
    from ..paths import bundled

    unknown = set(table) - _NK_KEYS
    if unknown:
        raise ParameterError(f"{where}: [{name}] has unknown key(s) {', '.join(sorted(unknown))} with nk_table "
                             f"(allowed: {', '.join(sorted(_NK_KEYS))})")
    bare, _, label = name.partition("@")
    if bare not in ("n", "k", "n_film"):
        raise ParameterError(f"{where}: [{name}] nk_table gives priors of n, k or n_film, not {name}")
    if "wavelength_um" in table:
        wavelength = _float(table["wavelength_um"], name, "wavelength_um", where)
    elif label:
        wavelength = float(label)
    else:
        raise ParameterError(f"{where}: [{name}] nk_table needs wavelength_um (or name the parameter {name}@LAMBDA)")
    source = Path(str(table["nk_table"]))
    try:
        if not source.is_file():  # beside the prior file, else one of the bundled tables
            source = Path(where).parent / source if (Path(where).parent / source).is_file() else bundled("nk", str(source))
        index = RefractiveIndex(source)(wavelength)
    except InputFileError as exc:
        raise ParameterError(f"{where}: [{name}] {exc}") from None
    except SpacepolError as exc:  # bundled(): no such file
        raise ParameterError(f"{where}: [{name}] nk_table {table['nk_table']}: {exc}") from None
    mu = float(index.imag if bare == "k" else index.real)
    relative = _float(table.get("relative_sigma", 0.05), name, "relative_sigma", where)
    sigma = _float(table["sigma"], name, "sigma", where) if "sigma" in table else max(relative * mu, 1e-3)
    lower = _float(table["lower"], name, "lower", where) if "lower" in table else max(0.0, mu - 6 * sigma)
    upper = _float(table["upper"], name, "upper", where) if "upper" in table else mu + 6 * sigma
    try:
        return TruncatedNormal(mu, sigma, lower, upper)
    except ParameterError as exc:
        raise ParameterError(f"{where}: [{name}] {exc}") from None


def prior_from_table(name: str, table: dict, where: str) -> Prior:
    """The Prior of one ``[name]`` table of a prior file (``uniform``, ``log_uniform``, ``normal``, ``fixed``, bounds,
    or an ``nk_table``); unknown keys and impossible values are one line naming ``where``."""
    if "nk_table" in table:
        return prior_from_nk_table(name, table, where)
    unknown = set(table) - _KEYS
    if unknown:
        raise ParameterError(f"{where}: [{name}] has unknown key(s) {', '.join(sorted(unknown))} (allowed: {', '.join(sorted(_KEYS))})")
    if "fixed" in table:
        if len(table) > 1:
            raise ParameterError(f"{where}: [{name}] 'fixed' cannot be combined with other keys")
        try:
            return Fixed(_float(table["fixed"], name, "fixed", where))
        except ParameterError as exc:
            if str(exc).startswith(where):
                raise
            raise ParameterError(f"{where}: [{name}] {exc}") from None
    kind = table.get("distribution", "uniform")
    try:
        lower = _float(table["lower"], name, "lower", where)
        upper = _float(table["upper"], name, "upper", where)
    except KeyError as missing:
        raise ParameterError(f"{where}: [{name}] needs {missing.args[0]}") from None
    try:
        if kind == "uniform":
            return Uniform(lower, upper)
        if kind == "loguniform":
            return LogUniform(lower, upper)
        if kind == "normal":
            return TruncatedNormal(_float(table.get("mu"), name, "mu", where), _float(table.get("sigma"), name, "sigma", where), lower, upper)
    except ParameterError as exc:
        raise ParameterError(f"{where}: [{name}] {exc}") from None
    raise ParameterError(f"{where}: [{name}] unknown distribution '{kind}' (uniform, loguniform, normal)")


def _float(value, name, key, where):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ParameterError(f"{where}: [{name}] {key} must be a number, got {value!r}")
    if not np.isfinite(value):
        raise ParameterError(f"{where}: [{name}] {key} must be a finite number, got {value!r}")
    return float(value)


def read_prior_file(path) -> dict[str, Prior]:
    """{parameter: Prior} of a prior TOML file, each table checked."""
    path = Path(path)
    data = read_toml(path, "prior")
    priors = {}
    for name, table in data.items():
        if not isinstance(table, dict):
            raise ParameterError(f"{path}: '{name}' must be a table [{name}]")
        priors[name] = prior_from_table(name, table, str(path))
    return priors


class PriorSet:
    """Priors of every parameter: free ones in ``names`` order, fixed ones held in ``fixed``."""

    def __init__(self, parameters: list[Parameter], overrides: dict[str, Prior] | None = None, where: str = "priors"):
        overrides = dict(overrides or {})
        known = {p.name for p in parameters}
        unknown = sorted(set(overrides) - known)
        if unknown:
            raise ParameterError(f"{where}: no parameter(s) {', '.join(unknown)} in this model (it has {', '.join(sorted(known))})")
        self.parameters = list(parameters)
        self.priors: dict[str, Prior] = {}
        for p in parameters:
            prior = overrides.get(p.name, p.effective_prior)
            lo, hi = p.physical
            if prior.lower < lo or prior.upper > hi:
                raise ParameterError(
                    f"{where}: prior {prior} of {p.name} reaches outside its physical range [{lo:g}, {hi:g}]"
                )
            self.priors[p.name] = prior
        self.names = [n for n, pr in self.priors.items() if not pr.is_fixed]
        free = [self.priors[n] for n in self.names]
        # Fast path of ln_prob when every free prior is uniform (the common case, and the hot path).
        self._all_uniform = all(type(pr) is Uniform for pr in free)
        self._lower = np.array([pr.lower for pr in free])
        self._upper = np.array([pr.upper for pr in free])
        self._uniform_constant = -float(np.sum(np.log(self._upper - self._lower))) if self._all_uniform else 0.0
        self.fixed = {n: pr.value for n, pr in self.priors.items() if pr.is_fixed}
        if not self.names:
            raise ParameterError(f"{where}: every parameter is fixed; nothing to infer")

    @property
    def ndim(self) -> int:
        """The number of free parameters."""
        return len(self.names)

    @property
    def bounds(self) -> np.ndarray:
        """(D, 2): each free parameter's support."""
        return np.array([self.priors[n].bounds for n in self.names])

    def ln_prob(self, theta) -> np.ndarray:
        """The joint log prior density of each row of theta (W, D)."""
        theta = np.atleast_2d(theta)
        if self._all_uniform:
            inside = np.all((theta >= self._lower) & (theta <= self._upper), axis=1)
            return np.where(inside, self._uniform_constant, -np.inf)
        total = np.zeros(theta.shape[0])
        for j, name in enumerate(self.names):
            total = total + self.priors[name].ln_prob(theta[:, j])
        return total

    def rescale(self, u) -> np.ndarray:
        """Rows of the unit cube (W, D) to parameter vectors, each through its prior's inverse CDF."""
        u = np.atleast_2d(u)
        return np.column_stack([self.priors[n].rescale(u[:, j]) for j, n in enumerate(self.names)])

    def to_unit(self, theta) -> np.ndarray:
        """Inverse of ``rescale`` (to ~1e-4 in u, by interpolating each monotone prior transform)."""
        theta = np.atleast_2d(theta)
        grid = np.linspace(0.0, 1.0, 10001)
        return np.column_stack([np.interp(theta[:, j], self.priors[n].rescale(grid), grid) for j, n in enumerate(self.names)])

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` parameter vectors drawn from the priors (size, D)."""
        return self.rescale(rng.uniform(size=(size, self.ndim)))

    def to_params(self, theta) -> dict[str, np.ndarray]:
        """theta (W, D) -> {name: (W,) array}, plus the fixed values as scalars."""
        theta = np.atleast_2d(theta)
        params = {name: theta[:, j] for j, name in enumerate(self.names)}
        params.update(self.fixed)
        return params

    def describe(self) -> dict[str, str]:
        """Every parameter's prior in words, by name (fixed ones included)."""
        return {name: str(prior) for name, prior in self.priors.items()}
