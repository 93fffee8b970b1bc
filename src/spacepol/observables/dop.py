"""Degree of polarization for unpolarized incidence: DOP = |S_pol| / S0 (after estimator effects)."""

from __future__ import annotations

import numpy as np

from ..errors import InputFileError
from ..priors import LogUniform
from ..physics.parameter import Parameter
from .base import ColumnObservable


class DOP(ColumnObservable):
    """The degree of polarization of the scattered light for unpolarized incidence (the paper's observable)."""

    name = "dop"
    scale_free = True
    label = "DOP"
    title = "DOP"
    listing_order = 10
    design_noise = 0.01
    noise = Parameter("sigma_dop", "", LogUniform(1e-4, 0.5), 0.01,
                      "DOP noise level (inferred: the file has no dop_err)", physical=(1e-12, np.inf))

    def check_value(self, column, value, path, line):
        super().check_value(column, value, path, line)
        if column == "dop" and not 0 <= value <= 1:
            raise InputFileError(path, f"DOP {value:g} outside [0, 1]", line=line, column=column)

    def predict(self, prediction):
        return {"dop": prediction.dop}
