"""A physical parameter of an effect: name, unit, default prior, and what it means."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..priors import Fixed, Prior


@dataclass(frozen=True)
class Parameter:
    """A model parameter: name, unit, prior, default, description; ``fixed`` ones are held at the default unless
    freed, values outside ``physical`` are impossible."""
    name: str
    unit: str
    prior: Prior
    default: float
    description: str
    fixed: bool = False  # held at ``default`` unless the user frees it (e.g. the paper's shadowing constants)
    physical: tuple[float, float] = (-np.inf, np.inf)  # values outside are impossible, not just unlikely

    def check(self, value, where: str = "") -> None:
        """Raise ParameterError if any of ``value`` is physically impossible."""
        lo, hi = self.physical
        values = np.asarray(value, dtype=float)
        bad = ~np.isfinite(values) | (values < lo) | (values > hi)
        if np.any(bad):
            first = values[bad].flat[0] if values.ndim else float(values)
            prefix = f"{where}: " if where else ""
            raise ParameterError(f"{prefix}{self.name} = {first:g} is impossible (allowed [{lo:g}, {hi:g}])")

    @property
    def effective_prior(self) -> Prior:
        """The prior the parameter gets: a Fixed prior at its default when it is fixed, else its own."""
        return Fixed(self.default) if self.fixed else self.prior

    def describe(self) -> str:
        """The parameter in one line: name, unit, prior, default and meaning."""
        unit = f" [{self.unit}]" if self.unit else ""
        state = f"fixed at {self.default:g}" if self.fixed else f"prior {self.prior}"
        return f"{self.name}{unit}: {self.description} ({state})"
