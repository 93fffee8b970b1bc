"""The 15 normalised Mueller elements m_ij = M_ij / M_11 (NIST's 1-based naming; M_11 itself is the
BRDF observable), Stokes basis as in DESIGN.md's geometry convention.

Noise: the file's ``m_err`` (one error for every element of a row) or ``m12_err ... m44_err``; without
them one inferred level per element group, since a polarimeter measures the groups with different
optics: the polarizance/diattenuation row and column (m12 m13 m14 m21 m31 m41, generator or analyser
alone), the linear block (m22 m23 m32 m33) and the elements that need a retarder on either side
(m24 m34 m42 m43 m44)."""

from __future__ import annotations

import numpy as np

from ..priors import LogUniform
from ..physics.arrays import array_module
from ..physics.parameter import Parameter
from .base import Observable

ELEMENTS = tuple(f"m{i}{j}" for i in range(1, 5) for j in range(1, 5))[1:]
GROUPS = {"pol": ("m12", "m13", "m14", "m21", "m31", "m41"), "lin": ("m22", "m23", "m32", "m33"),
          "circ": ("m24", "m34", "m42", "m43", "m44")}
_WORDS = {"pol": "polarizance and diattenuation elements m12 m13 m14 m21 m31 m41",
          "lin": "linear block m22 m23 m32 m33", "circ": "circular elements m24 m34 m42 m43 m44"}
NOISE = {g: Parameter(f"sigma_m_{g}", "", LogUniform(1e-4, 0.5), 0.01, f"noise of the normalised Mueller {_WORDS[g]} (inferred)",
                      physical=(1e-12, np.inf)) for g in GROUPS}
GROUP_OF = {e: g for g, members in GROUPS.items() for e in members}


def index(element: str) -> tuple[int, int]:
    """Zero-based (row, column) of a Mueller element name ("m34" -> (2, 3))."""
    return int(element[1]) - 1, int(element[2]) - 1


def normalised(mueller) -> dict[str, np.ndarray]:
    """{m_ij: M_ij / M_11} from a (4, 4, ...) Mueller array (0 where M_11 = 0)."""
    xp = array_module(mueller)
    m11 = xp.where(mueller[0, 0] > 0, mueller[0, 0], np.inf)  # divide, not multiply by 1/M11: M11 may be subnormal
    return {e: mueller[index(e)] / m11 for e in ELEMENTS}


class Mueller(Observable):
    """The 15 normalised Mueller elements m_ij = M_ij / M_11, with an inferred noise per element group (polarizance
    and diattenuation, the linear block, the circular elements) where the file gives no errors."""

    name = "mueller"
    scale_free = True
    channels = ELEMENTS
    label = "m_ij = M_ij / M_11"
    needs_mueller = True
    contains = ("stokes", "dop", "aop")  # m21, m31, m41 are S1, S2, S3 / S0 for unpolarized incidence

    def present(self, data):
        return data.mueller is not None

    def observed(self, data):
        return normalised(data.mueller)

    def errors(self, data):
        err = getattr(data, "mueller_err", None)
        return None if err is None else {e: err[index(e)] for e in ELEMENTS}

    def predict(self, prediction):
        return normalised(prediction.mueller)

    def noise_parameter(self, channel):
        return NOISE[GROUP_OF[channel]]

    def dims(self, channel):
        return ["geometry"]
