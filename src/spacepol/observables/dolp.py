"""Degree of linear polarization for unpolarized incidence, DoLP = sqrt(S1^2 + S2^2) / S0: what a micro-polarizer
(division-of-focal-plane) camera measures, with its 0/45/90/135 deg analysers and no retarder. It equals DOP where
the scattered light has no circular part (S3 = 0). File columns ``dolp`` and ``dolp_err``; without errors one
inferred noise level. The prediction is the Stokes vector's own (measurement effects on the DOP, such as
``dop_bias``, act on DOP only)."""

from __future__ import annotations

import numpy as np

from ..errors import InputFileError
from ..physics.compiled import degree_of_polarization
from ..physics.parameter import Parameter
from ..priors import LogUniform
from .base import ColumnObservable


class DoLP(ColumnObservable):
    """The degree of linear polarization sqrt(S1^2 + S2^2) / S0 of the scattered light (unpolarized incidence)."""

    name = "dolp"
    scale_free = True
    label = "DoLP"
    title = "DoLP"
    listing_order = 60
    design_noise = 0.01
    contained_in = ("stokes", "mueller")  # q and u give it; the Mueller matrix's m21, m31
    noise = Parameter("sigma_dolp", "", LogUniform(1e-4, 0.5), 0.01,
                      "DoLP noise level (inferred: the file has no dolp_err)", physical=(1e-12, np.inf))

    def check_value(self, column, value, path, line):
        super().check_value(column, value, path, line)
        if column == "dolp" and not 0 <= value <= 1:
            raise InputFileError(path, f"DoLP {value:g} outside [0, 1]", line=line, column=column)

    def predict(self, prediction):
        s = prediction.stokes
        return {"dolp": degree_of_polarization((s[0], s[1], s[2], 0.0 * s[3]))}
