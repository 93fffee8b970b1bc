"""What an observable is: a measured quantity the likelihood compares with the model.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import math

import jax.numpy as jnp
import numpy as np

from ..errors import InputFileError
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
    contained_in: tuple[str, ...] = ()  # the same relation declared by the contained one (a new observable's own file)
    aliases: tuple[str, ...] = ()  # other names ``--observables`` takes for it (its channels, e.g. q and u)
    title: str = ""  # in words, for sentences ("DOP", "the Mueller matrix")
    listing_order: int = 100  # where it is listed among the observables (lists, summaries, figures)
    # experiment design: the noise assumed for a candidate measurement where the data do not give one (None: this
    # observable is not a candidate), relative (a fraction of the value, as BRDF's) or absolute
    design_noise: float | None = None
    relative_noise: bool = False

    # reading a measurement file: the columns its values come from (all of them together), optional ones, the
    # columns of their 1-sigma errors, and the Dataset arrays it keeps them in (rows on the last axis)
    columns: tuple[str, ...] = ()
    optional_columns: tuple[str, ...] = ()
    error_columns: tuple[str, ...] = ()
    arrays: tuple[str, ...] = ()

    def present(self, data) -> bool:
        """Whether the data set holds this observable."""
        return data.get(self.arrays[0]) is not None

    def in_header(self, header) -> bool:
        """Whether a file's header holds this observable."""
        return any(c in header for c in self.columns)

    def check_header(self, header, path, line) -> None:
        """All of ``columns`` or none; an error column only with the values it belongs to (one line otherwise)."""
        given = [c for c in self.columns if c in header]
        if given and len(given) < len(self.columns):
            missing = ", ".join(c for c in self.columns if c not in header)
            raise InputFileError(path, f"{self.title or self.name} data need all of {', '.join(self.columns)}; missing "
                                       f"{missing}", line=line)
        extra = [c for c in self.error_columns + self.optional_columns if c in header]
        if extra and not given:
            raise InputFileError(path, f"column '{extra[0]}' without '{self.columns[0]}'", line=line)

    def check_value(self, column: str, value: float, path, line) -> None:
        """One cell of one of its columns (a negative error here; subclasses add their ranges)."""
        if column in self.error_columns and value < 0:
            raise InputFileError(path, f"negative uncertainty {value:g}", line=line, column=column)

    def check_row(self, values: dict, path, line) -> None:
        """One row's cells together (a Stokes vector's length against s0): one line where they are impossible."""

    def read(self, columns: dict[str, np.ndarray], n: int) -> dict[str, np.ndarray]:
        """The Dataset arrays from a file's columns (every column of the file, ``n`` rows)."""
        return {c: columns[c] for c in self.columns + self.optional_columns + self.error_columns if c in columns}

    def observed(self, data) -> dict[str, np.ndarray]:
        """{channel: (N,) measured values}."""
        raise NotImplementedError

    def errors(self, data) -> dict[str, np.ndarray] | None:
        """{channel: (N,) 1-sigma errors} from the file, or None when the noise is to be inferred."""
        return None

    def predict(self, prediction) -> dict[str, np.ndarray]:
        """{channel: (..., N) model values} from a ``physics.model.Prediction``."""
        raise NotImplementedError

    def predict_stacked(self, prediction):
        """All channels' predictions as one array (channels, ..., N) in ``channels``' order. The base class gives
        None, and the likelihood then takes the channels one by one; an observable that overrides it always returns
        the array, and promises that its ``residual`` and ``log_density`` do not depend on the channel, so the
        likelihood forms them on the whole array: one compiled loop instead of one per channel (XLA compiles each
        loop separately)."""
        return None

    def noise_space(self, channel: str, mu, inferred: bool):
        """A prediction in the space where the noise is Gaussian (the value itself; log BRDF for a relative noise)."""
        return mu

    def residual(self, channel: str, y, mu, inferred: bool):
        """Measured minus predicted, in the space where the noise is Gaussian."""
        return self.noise_space(channel, y, inferred) - self.noise_space(channel, mu, inferred)

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

    def reciprocal_differences(self, channel: str, observed: dict, pairs: np.ndarray, inferred: bool):
        """Differences of ``channel`` between reciprocal pairs (source and detector swapped; ``pairs`` (K, 2) row
        indices, a row paired with itself where the geometry is its own reciprocal) that a passive sample makes pure
        noise, in the residual's space; None where reciprocity says nothing about this observable."""
        return None

    def reciprocal_members(self, channel: str, pairs: np.ndarray):
        """Which measured numbers each of ``reciprocal_differences``' differences takes, in its order: ((rows, channel)
        of its first member, (rows, channel) of its second); the measured noise divides a difference by the noise
        profile there (``noise_profile``). None: the differences are taken as they are."""
        return None

    def noise_profile(self, channel: str, data) -> np.ndarray | None:
        """How an inferred noise level varies over the rows: (N,) factors on it, or None for a constant level."""
        return None

    def noise_parameter(self, channel: str) -> Parameter:
        """The nuisance parameter holding ``channel``'s noise level when the file gives no errors."""
        return self.noise

    def axis_label(self, channel: str) -> str:
        """A figure's axis label for one channel (the observable's ``label``; the channel's name among several)."""
        return self.label if len(self.channels) == 1 else channel

    def dims(self, channel: str) -> list[str]:
        """ArviZ dimensions of one channel's array over the geometries."""
        return ["geometry"]


class ColumnObservable(Observable):
    """One channel: the file column and Dataset array of its own name, its errors in ``NAME_err``."""

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.name and not cls.columns:
            cls.columns, cls.error_columns = (cls.name,), (f"{cls.name}_err",)
            cls.arrays = (cls.name, f"{cls.name}_err")
        if cls.name and not cls.channels:
            cls.channels = (cls.name,)

    def observed(self, data):
        return {self.name: data.get(self.name)}

    def errors(self, data):
        err = data.get(f"{self.name}_err")
        return None if err is None else {self.name: err}
