"""Priors as objects (bilby style): ``ln_prob``, ``sample`` and ``rescale`` from the unit cube.

``rescale`` lets the GA, nlopt and differential evolution search the very cube the sampler
sees: a point ``u`` in [0, 1]^d maps to parameter values through each prior's inverse CDF; ``cdf`` is
its exact inverse. ``rescale`` and ``ln_prob`` also take JAX arrays (gradient methods trace them).
"""

from __future__ import annotations

from dataclasses import dataclass

import jax
import jax.scipy.special
import numpy as np
from scipy import special

from .errors import ParameterError


class Prior:
    """A one-dimensional prior.  Subclasses define ``ln_prob``, ``rescale`` and ``bounds``."""

    lower: float
    upper: float

    def ln_prob(self, x):
        """The log density at x (numpy or JAX arrays); -inf outside [lower, upper]."""
        raise NotImplementedError

    def rescale(self, u):
        """Inverse CDF: maps u in [0, 1] to a parameter value (numpy or JAX arrays)."""
        raise NotImplementedError

    def cdf(self, x):
        """The CDF, the inverse of ``rescale`` on [lower, upper] (numpy)."""
        raise NotImplementedError

    def sample(self, rng: np.random.Generator, size=None):
        """Draws from the prior (inverse-CDF sampling with ``rng``)."""
        return self.rescale(rng.uniform(size=size))

    @property
    def bounds(self) -> tuple[float, float]:
        """(lower, upper): the support."""
        return (self.lower, self.upper)

    @property
    def is_fixed(self) -> bool:
        """Whether the parameter is held at one value (``Fixed``) rather than inferred."""
        return False


def _array(u):
    """u as a float array of its own kind (a traced JAX value stays one)."""
    return u if isinstance(u, jax.Array) else np.asarray(u, dtype=float)


def _module(u):
    return jax.numpy if isinstance(u, jax.Array) else np


def _check_interval(lower: float, upper: float, what: str) -> None:
    if not (np.isfinite(lower) and np.isfinite(upper)):
        raise ParameterError(f"{what}: bounds must be finite, got [{lower}, {upper}]")
    if not lower < upper:
        raise ParameterError(f"{what}: lower bound {lower:g} is not below upper bound {upper:g}")


@dataclass(frozen=True)
class Uniform(Prior):
    """Uniform on [lower, upper] (finite bounds)."""

    lower: float
    upper: float

    def __post_init__(self):
        _check_interval(self.lower, self.upper, "Uniform prior")

    def ln_prob(self, x):
        x, xp = _array(x), _module(x)
        inside = (x >= self.lower) & (x <= self.upper)
        return xp.where(inside, -np.log(self.upper - self.lower), -np.inf)

    def rescale(self, u):
        return self.lower + (self.upper - self.lower) * _array(u)

    def cdf(self, x):
        return np.clip((np.asarray(x, dtype=float) - self.lower) / (self.upper - self.lower), 0.0, 1.0)

    def __str__(self):
        return f"Uniform({self.lower:g}, {self.upper:g})"


@dataclass(frozen=True)
class LogUniform(Prior):
    """Uniform in log(x): scale-invariant, for positive quantities spanning decades."""

    lower: float
    upper: float

    def __post_init__(self):
        _check_interval(self.lower, self.upper, "LogUniform prior")
        if self.lower <= 0:
            raise ParameterError(f"LogUniform prior: lower bound must be > 0, got {self.lower}")

    def ln_prob(self, x):
        x, xp = _array(x), _module(x)
        inside = (x >= self.lower) & (x <= self.upper)
        with np.errstate(divide="ignore", invalid="ignore"):
            value = -xp.log(x) - np.log(np.log(self.upper / self.lower))
        return xp.where(inside, value, -np.inf)

    def rescale(self, u):
        return self.lower * (self.upper / self.lower) ** _array(u)

    def cdf(self, x):
        x = np.clip(np.asarray(x, dtype=float), self.lower, self.upper)
        return np.log(x / self.lower) / np.log(self.upper / self.lower)

    def __str__(self):
        return f"LogUniform({self.lower:g}, {self.upper:g})"


@dataclass(frozen=True)
class TruncatedNormal(Prior):
    """Normal(mu, sigma) truncated to [lower, upper]."""

    mu: float
    sigma: float
    lower: float
    upper: float

    def __post_init__(self):
        _check_interval(self.lower, self.upper, "TruncatedNormal prior")
        if not np.isfinite(self.mu):
            raise ParameterError(f"TruncatedNormal prior: mu must be finite, got {self.mu}")
        if not (self.sigma > 0 and np.isfinite(self.sigma)):
            raise ParameterError(f"TruncatedNormal prior: sigma must be finite and > 0, got {self.sigma}")
        lo, hi = self._cdf_bounds()
        if not hi - lo > 1e-300:
            raise ParameterError(f"normal(mu={self.mu:g}, sigma={self.sigma:g}) puts no probability on "
                                 f"[{self.lower:g}, {self.upper:g}] (mu lies {min(abs(self.mu - self.lower), abs(self.mu - self.upper)) / self.sigma:.3g} "
                                 f"sigma outside it)")

    def _cdf_bounds(self):
        a = (self.lower - self.mu) / self.sigma
        b = (self.upper - self.mu) / self.sigma
        return special.ndtr(a), special.ndtr(b)

    def ln_prob(self, x):
        x, xp = _array(x), _module(x)
        lo, hi = self._cdf_bounds()
        z = (x - self.mu) / self.sigma
        value = -0.5 * z**2 - np.log(self.sigma * np.sqrt(2 * np.pi) * (hi - lo))
        return xp.where((x >= self.lower) & (x <= self.upper), value, -np.inf)

    def rescale(self, u):
        lo, hi = self._cdf_bounds()
        u = _array(u)
        ndtri = jax.scipy.special.ndtri if isinstance(u, jax.Array) else special.ndtri
        return self.mu + self.sigma * ndtri(lo + (hi - lo) * u)

    def cdf(self, x):
        lo, hi = self._cdf_bounds()
        x = np.clip(np.asarray(x, dtype=float), self.lower, self.upper)
        return np.clip((special.ndtr((x - self.mu) / self.sigma) - lo) / (hi - lo), 0.0, 1.0)

    def __str__(self):
        return f"TruncatedNormal({self.mu:g}, {self.sigma:g}, [{self.lower:g}, {self.upper:g}])"


@dataclass(frozen=True)
class Fixed(Prior):
    """A parameter held at one value: not sampled, not searched."""

    value: float

    def __post_init__(self):
        if not np.isfinite(self.value):
            raise ParameterError(f"fixed value must be a finite number, got {self.value}")

    @property
    def lower(self):  # type: ignore[override]
        """The fixed value (a point prior's lower bound)."""
        return self.value

    @property
    def upper(self):  # type: ignore[override]
        """The fixed value (a point prior's upper bound)."""
        return self.value

    @property
    def is_fixed(self) -> bool:
        return True

    def ln_prob(self, x):
        x = np.asarray(x, dtype=float)
        return np.where(x == self.value, 0.0, -np.inf)

    def rescale(self, u):
        return np.full_like(np.asarray(u, dtype=float), self.value)

    def cdf(self, x):
        return np.where(np.asarray(x, dtype=float) >= self.value, 1.0, 0.0)

    def __str__(self):
        return f"Fixed({self.value:g})"
