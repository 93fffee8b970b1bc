"""What an observable is: a measured quantity the likelihood compares with the model.

An observable has one or more *channels*, each a vector over the N measured geometries (DOP has one,
the normalised Stokes parameters two, q and u, the normalised Mueller matrix fifteen, m12 ... m44).
It says from the model's output what each channel predicts, how a residual is formed, how the noise is
modelled (the file's errors per row, or one inferred noise level for its channel group), its log
density, how replicate data are drawn and its ArviZ dimensions. The likelihood, the residual analysis,
the figures and the InferenceData use channels generically; adding an observable is one new file
registered in ``observables/__init__.py``.

``predict``, ``residual`` and ``log_density`` also run inside the compiled likelihood, on JAX arrays:
they compute with ``array_module(...)`` (numpy for numpy arrays, jax.numpy for JAX ones).
"""

from __future__ import annotations

import math

import jax.numpy as jnp
import numpy as np

from ..physics.arrays import array_module
from ..physics.parameter import Parameter

_LOG_2PI = math.log(2 * math.pi)


class Observable:
    """A measured quantity the likelihood can fit (DOP, BRDF, Stokes, AoP, the Mueller matrix): its ``channels``,
    whether the file holds it (``present``), the observed numbers and their errors, the model's prediction of
    it, and the nuisance noise level used when the file gives no errors. Found through the observable registry."""

    name: str = ""
    channels: tuple[str, ...] = ()
    label: str = ""  # axis label
    needs_mueller: bool = False  # predictions need the model's full Mueller matrix
    # predictions are ratios of the Stokes (Mueller) elements at each geometry, unchanged when all of them are
    # multiplied by one positive number: the likelihood may then skip the model's divisions (compiled.Program)
    scale_free: bool = False
    noise: Parameter | None = None  # the nuisance noise level of the channel group when the file gives none
    # observables whose numbers this one already holds (the normalised Mueller matrix's first column is
    # the Stokes vector, which gives DOP and AoP): by default only the fullest of them is fitted, so no
    # measured number is counted twice
    contains: tuple[str, ...] = ()

    def present(self, data) -> bool:
        """Whether the data set holds this observable."""
        raise NotImplementedError

    def observed(self, data) -> dict[str, np.ndarray]:
        """{channel: (N,) measured values}."""
        raise NotImplementedError

    def errors(self, data) -> dict[str, np.ndarray] | None:
        """{channel: (N,) 1-sigma errors} from the file, or None when the noise is to be inferred."""
        return None

    def predict(self, prediction) -> dict[str, np.ndarray]:
        """{channel: (..., N) model values} from a ``physics.model.Prediction``."""
        raise NotImplementedError

    def residual(self, channel: str, y, mu, inferred: bool):
        """Measured minus predicted, in the space where the noise is Gaussian."""
        return y - mu

    def log_density(self, resid, scale):
        """Gaussian log density of the residuals at noise ``scale`` (same shape, broadcast)."""
        xp = array_module(resid, scale)
        if xp is jnp:
            return -0.5 * jnp.square(resid / scale) - (jnp.log(scale) + 0.5 * _LOG_2PI)
        z = np.divide(resid, scale)  # in place from here: full-Mueller data make these arrays megabytes
        np.square(z, out=z)
        z *= -0.5
        z -= np.log(scale) + 0.5 * _LOG_2PI
        return z

    def replicate(self, channel: str, mu, scale, inferred: bool, rng: np.random.Generator):
        """Replicate data drawn like the measurement: prediction plus noise in the residual's space."""
        return mu + scale * rng.standard_normal(np.shape(mu))

    def noise_profile(self, channel: str, data) -> np.ndarray | None:
        """How an inferred noise level varies over the rows: (N,) factors on it, or None for a constant level."""
        return None

    def noise_parameter(self, channel: str) -> Parameter:
        """The nuisance parameter holding ``channel``'s noise level when the file gives no errors."""
        return self.noise

    def dims(self, channel: str) -> list[str]:
        """ArviZ dimensions of one channel's array over the geometries."""
        return ["geometry"]


class ColumnObservable(Observable):
    """One channel read from the Dataset attribute of the same name, with its errors in ``NAME_err``."""

    def present(self, data):
        return getattr(data, self.name) is not None

    def observed(self, data):
        return {self.name: getattr(data, self.name)}

    def errors(self, data):
        err = getattr(data, f"{self.name}_err")
        return None if err is None else {self.name: err}
