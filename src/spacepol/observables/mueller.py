"""The 15 normalised Mueller elements m_ij = M_ij / M_11 (NIST's 1-based naming; M_11 itself is the
BRDF observable), Stokes basis as in DESIGN.md's geometry convention.

Noise: the file's ``m_err`` (one error for every element of a row) or ``m12_err ... m44_err``; without
them one inferred level per element group, since a polarimeter measures the groups with different
optics: the polarizance/diattenuation row and column (m12 m13 m14 m21 m31 m41, generator or analyser
alone), the linear block (m22 m23 m32 m33) and the elements that need a retarder on either side
(m24 m34 m42 m43 m44)."""

from __future__ import annotations

import numpy as np

from ..errors import InputFileError, ParameterError
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
RECIPROCITY_SIGNS = np.array([1.0, 1.0, -1.0, 1.0])  # the diagonal of Q in M(r -> i, -dphi) = Q M(i -> r, dphi)^T Q


def index(element: str) -> tuple[int, int]:
    """Zero-based (row, column) of a Mueller element name ("m34" -> (2, 3))."""
    return int(element[1]) - 1, int(element[2]) - 1


def check_element(value, path, line, column):
    """A normalised Mueller element M_ij / M_11 lies in [-1, 1]."""
    if abs(value) > 1:
        raise InputFileError(path, f"normalised Mueller element {value:g} outside [-1, 1]", line=line, column=column)


def check_first_column(m21, m31, m41, path, line, column):
    """The state unpolarized light leaves in (m21, m31, m41): its degree of polarization cannot exceed 1."""
    dop = float(np.sqrt(m21**2 + m31**2 + m41**2))
    if dop > 1:
        raise InputFileError(path, f"m21, m31, m41 imply DOP {dop:.4g} > 1 for unpolarized light", line=line, column=column)


def normalised_elements(mueller):
    """M_ij / M_11 for the 15 elements after M_11, (15, ...), in ``ELEMENTS``' order, from a (4, 4, ...) Mueller array
    (0 where M_11 = 0): the flattened matrix's elements after M_11 are m12 ... m44, so one slice and one division."""
    xp = array_module(mueller)
    m11 = xp.where(mueller[0, 0] > 0, mueller[0, 0], np.inf)  # divide, not multiply by 1/M11: M11 may be subnormal
    return xp.reshape(mueller, (16,) + mueller.shape[2:])[1:] / m11


def normalised(mueller) -> dict[str, np.ndarray]:
    """{m_ij: M_ij / M_11} from a (4, 4, ...) Mueller array (0 where M_11 = 0)."""
    return dict(zip(ELEMENTS, normalised_elements(mueller)))


class Mueller(Observable):
    """The 15 normalised Mueller elements m_ij = M_ij / M_11, with an inferred noise per element group (polarizance
    and diattenuation, the linear block, the circular elements) where the file gives no errors."""

    name = "mueller"
    scale_free = True
    channels = ELEMENTS
    label = "m_ij = M_ij / M_11"
    title = "the Mueller matrix"
    listing_order = 50
    design_noise = 0.01
    needs_mueller = True
    contains = ("stokes", "dop", "aop")  # m21, m31, m41 are S1, S2, S3 / S0 for unpolarized incidence
    columns = ELEMENTS
    error_columns = ("m_err",) + tuple(f"{e}_err" for e in ELEMENTS)
    # (4, 4, N): the BRDF Mueller matrix (M_11 = BRDF, or 1) and m_ij's errors; (3, N): factors on each group's
    # inferred noise level over the rows (``noise_profile``), set by a caller, never read from a file
    arrays = ("mueller", "mueller_err", "mueller_noise_profile")

    def check_header(self, header, path, line):
        """All 15 normalised elements or none; errors as m_err, or per element for all 15 (m_err covering the rest)."""
        given = [m for m in ELEMENTS if m in header]
        if given and len(given) < 15:
            missing = [m for m in ELEMENTS if m not in header]
            raise InputFileError(path, f"Mueller data need all 15 elements m12 ... m44; missing {', '.join(missing)}", line=line)
        errors = [f"{m}_err" for m in ELEMENTS if f"{m}_err" in header]
        if (errors or "m_err" in header) and not given:
            raise InputFileError(path, f"column '{(errors or ['m_err'])[0]}' without the Mueller elements m12 ... m44", line=line)
        if errors and len(errors) < 15 and "m_err" not in header:
            missing = [f"{m}_err" for m in ELEMENTS if f"{m}_err" not in header]
            raise InputFileError(path, f"per-element Mueller errors need all 15 columns (or one m_err for the rest); "
                                       f"missing {', '.join(missing)}", line=line)

    def check_value(self, column, value, path, line):
        super().check_value(column, value, path, line)
        if column in ELEMENTS:
            check_element(value, path, line, column)

    def check_row(self, values, path, line):
        check_first_column(values["m21"], values["m31"], values["m41"], path, line, "m21, m31, m41")

    def read(self, columns, n):
        """(4, 4, N) Mueller matrix (M_11 = the file's BRDF, or 1 without one) and its errors (None without any)."""
        m11 = columns.get("brdf", np.ones(n))
        mueller = np.empty((4, 4, n))
        errors = np.full((4, 4, n), np.nan)
        mueller[0, 0] = m11
        for name in ELEMENTS:
            mueller[index(name)] = m11 * columns[name]
            err = columns.get(f"{name}_err", columns.get("m_err"))
            if err is not None:
                errors[index(name)] = err
        has_errors = any(c in columns for c in self.error_columns)
        return {"mueller": mueller, "mueller_err": errors if has_errors else None}

    def observed(self, data):
        return normalised(data.get("mueller"))

    def errors(self, data):
        err = data.get("mueller_err")
        return None if err is None else {e: err[index(e)] for e in ELEMENTS}

    def noise_profile(self, channel, data):
        """The rows' factors on the channel's group level from the data set's ``mueller_noise_profile`` ((3, N),
        ``GROUPS``' order; ``MirrorScatter.noise_profile`` makes one from the measurement's own spread), or None."""
        profile = data.get("mueller_noise_profile")
        if profile is None:
            return None
        profile = np.asarray(profile, float)
        wanted = (f"{data.source}: mueller_noise_profile must hold {len(GROUPS)} x {len(data)} finite factors > 0 "
                  "(one per element group and row)")
        if profile.shape != (len(GROUPS), len(data)):
            raise ParameterError(f"{wanted}; it has shape {profile.shape}")
        if not np.all(np.isfinite(profile) & (profile > 0)):
            raise ParameterError(f"{wanted}; it has values <= 0 or not finite")
        return profile[list(GROUPS).index(GROUP_OF[channel])]

    def predict(self, prediction):
        return normalised(prediction.mueller)

    def predict_stacked(self, prediction):
        """The 15 elements over M_11, (15, ..., N) (``normalised_elements``): one loop for the 15 channels in the
        compiled likelihood, not 15, which halves its compilation."""
        return normalised_elements(prediction.mueller)

    def reciprocal_differences(self, channel, observed, pairs, inferred):
        """m_ij(r -> i) - q_i q_j m_ji(i -> r): reciprocity transposes the matrix (Q = diag(1, 1, -1, 1))."""
        i, j = index(channel)
        (rows_b, _), (rows_a, mirror) = self.reciprocal_members(channel, pairs)
        return observed[channel][rows_b] - RECIPROCITY_SIGNS[i] * RECIPROCITY_SIGNS[j] * observed[mirror][rows_a]

    def reciprocal_members(self, channel, pairs):
        """(rows b, m_ij) and (rows a, m_ji) of each pair (a, b) whose difference says something."""
        i, j = index(channel)
        a, b = pairs.T
        keep = (a != b) | (i < j)  # a self-pair constrains only the off-diagonal elements, each pair once
        return (b[keep], channel), (a[keep], f"m{j + 1}{i + 1}")

    def noise_parameter(self, channel):
        return NOISE[GROUP_OF[channel]]

    def dims(self, channel):
        return ["geometry"]
