"""Normalised Stokes parameters q = S1/S0 and u = S2/S0 for unpolarized incidence (s-polarized light has
q > 0). They carry the sign and orientation of the polarization that DOP discards (DOP = sqrt(q^2 + u^2)
when S3 = 0), so use them instead of DOP, not with it. One inferred noise level for both."""

from __future__ import annotations

import numpy as np

from ..errors import InputFileError
from ..priors import LogUniform
from ..physics.arrays import array_module
from ..physics.parameter import Parameter
from .base import Observable


def _normalised(stokes, row):
    s0 = array_module(stokes).where(stokes[0] > 0, stokes[0], np.inf)
    return stokes[row] / s0


class Stokes(Observable):
    """The normalised Stokes parameters q = S1/S0 and u = S2/S0 of the scattered light (unpolarized incidence)."""

    name = "stokes"
    scale_free = True
    channels = ("q", "u")
    aliases = ("q", "u")
    label = "normalised Stokes"
    title = "Stokes"
    listing_order = 40
    contains = ("dop", "aop")
    columns = ("s0", "s1", "s2")
    optional_columns = ("s3",)
    arrays = ("stokes",)
    noise = Parameter("sigma_qu", "", LogUniform(1e-4, 0.5), 0.01,
                      "noise of the normalised Stokes parameters q, u (inferred)", physical=(1e-12, np.inf))

    def axis_label(self, channel):
        return f"{channel} = S{'12'[self.channels.index(channel)]}/S0"

    def check_value(self, column, value, path, line):
        if column == "s0" and value < 0:
            raise InputFileError(path, f"negative intensity {value:g}", line=line, column=column)

    def check_row(self, values, path, line):
        """A possible polarization state: the polarized part no larger than s0 (a degree of polarization in [0, 1])."""
        polarized = float(np.sqrt(values["s1"] ** 2 + values["s2"] ** 2 + values.get("s3", 0.0) ** 2))
        if polarized > values["s0"]:
            parts = "s1, s2, s3" if "s3" in values else "s1, s2"
            raise InputFileError(path, f"Stokes vector with |({parts})| = {polarized:g} above s0 = {values['s0']:g} "
                                       "(a degree of polarization above 1)", line=line, column="s1")

    def read(self, columns, n):
        """(4, N) s0 ... s3 (s3 = 0 where the file has none)."""
        return {"stokes": np.array([columns["s0"], columns["s1"], columns["s2"], columns.get("s3", np.zeros(n))])}

    def observed(self, data):
        stokes = data.get("stokes")
        return {"q": _normalised(stokes, 1), "u": _normalised(stokes, 2)}

    def predict(self, prediction):
        return {"q": _normalised(prediction.stokes, 1), "u": _normalised(prediction.stokes, 2)}
