"""Degree of circular polarization for unpolarized incidence, DoCP = S3 / S0, signed (S3 > 0 for right-handed light,
as in the Stokes convention of DESIGN.md): what a circular analyser (a quarter-wave plate before a linear
polarizer) measures. A single reflection of unpolarized light leaves S3 = 0; S3 comes from depolarizing or multiply
scattering surfaces, so DoCP is a test of those terms. File columns ``docp`` and ``docp_err`` (in [-1, 1]); without
errors one inferred noise level."""

from __future__ import annotations

import numpy as np

from ..errors import InputFileError
from ..physics.arrays import array_module
from ..physics.parameter import Parameter
from ..priors import LogUniform
from .base import ColumnObservable


class DoCP(ColumnObservable):
    """The signed degree of circular polarization S3 / S0 of the scattered light (unpolarized incidence)."""

    name = "docp"
    scale_free = True
    label = "DoCP = S3/S0"
    title = "DoCP"
    listing_order = 70
    design_noise = 0.01
    contained_in = ("mueller",)  # its m41
    noise = Parameter("sigma_docp", "", LogUniform(1e-4, 0.5), 0.01,
                      "DoCP noise level (inferred: the file has no docp_err)", physical=(1e-12, np.inf))

    def check_value(self, column, value, path, line):
        super().check_value(column, value, path, line)
        if column == "docp" and not -1 <= value <= 1:
            raise InputFileError(path, f"DoCP {value:g} outside [-1, 1]", line=line, column=column)

    def predict(self, prediction):
        s = prediction.stokes
        return {"docp": s[3] / array_module(s).where(s[0] > 0, s[0], np.inf)}
