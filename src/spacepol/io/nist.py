"""NIST full Mueller-matrix BRDF layout (Germer, Appl. Opt. 56, 2017; data/ptfe/).

Columns: ``lambda`` (um), ``thetai`` (deg; incidence stored negative), ``phii``, ``thetar``, ``phir`` (deg), ``fr11``
(sr^-1), then the 15 ratios m12 ... m44 = f_rij / f_r11. Angles: dphi = phi_source - phi_r with phi_source = phi_i +
180 deg when theta_i < 0 (the specular plane at dphi = 180 deg, as DESIGN.md fixes). Polarization frames: the file's
matrices are in SCATMECH's x-y basis ("xyxy": each beam's frame tied to the sample's x and y axes), spacepol's in the
s-p basis of each beam's plane of incidence ("psps"); the exit side turns by the scattering azimuth phi_s = 180 - dphi,
M_sp = L(phi_s) M_xy (``xy_to_sp``; checked against SCATMECH's two bases in tests/test_nist_frames.py).
"""

from __future__ import annotations

import csv
import io as _io

import numpy as np

from ..errors import InputFileError
from ..observables.mueller import check_element, check_first_column
from .cells import is_blank_row, parse_number
from .dataset import Dataset

_RATIO_NAMES = [f"m{i}{j}" for i in range(1, 5) for j in range(1, 5)][1:]


def is_nist_header(header) -> bool:
    """True for the header of NIST's Mueller BRDF files (lambda, thetai, phii, ... and 16 ratio columns)."""
    lowered = [h.lower() for h in header]
    return len(lowered) >= 21 and lowered[0] == "lambda" and lowered[1] == "thetai"


def xy_to_sp(mueller, phi_s_deg):
    """Mueller matrices (4, 4, N) from SCATMECH's x-y basis to the s-p basis: the exit beam's frame turned by the
    scattering azimuth ``phi_s_deg`` (0 = the specular direction), L(phi_s) M with L(a) the rotator
    [[1, 0, 0, 0], [0, cos 2a, sin 2a, 0], [0, -sin 2a, cos 2a, 0], [0, 0, 0, 1]]. The incident frames agree (phi_i = 0)."""
    a = 2.0 * np.radians(phi_s_deg)
    c, s = np.cos(a), np.sin(a)
    out = np.array(mueller, float, copy=True)
    out[1], out[2] = c * mueller[1] + s * mueller[2], -s * mueller[1] + c * mueller[2]
    return out


def _wrap_deg(angle):
    return (np.asarray(angle) + 180.0) % 360.0 - 180.0


def read_nist_rows(path, header, lines, header_line, meta):

    """The rows of a NIST Mueller BRDF file as a Dataset: angles converted to the spacepol convention, the Mueller
    matrix from fr11 and the ratios, each value checked."""
    if len(header) != 21:
        raise InputFileError(path, f"NIST Mueller layout needs 21 columns, header has {len(header)}", line=header_line)
    names = ["lambda", "thetai", "phii", "thetar", "phir", "fr11"] + _RATIO_NAMES
    rows = []
    for offset, row in enumerate(csv.reader(_io.StringIO("\n".join(lines))), start=1):
        line = header_line + offset
        if is_blank_row(row, path, line):
            continue
        if len(row) != 21:
            raise InputFileError(path, f"{len(row)} fields, header has 21", line=line)
        values = [parse_number(c.strip(), path, line, header[i]) for i, c in enumerate(row)]
        for col in (1, 3):
            if abs(values[col]) >= 90:
                raise InputFileError(path, f"angle {values[col]:g} deg: |angle| must be below 90", line=line, column=header[col])
        if values[0] <= 0:
            raise InputFileError(path, f"wavelength {values[0]:g} um must be positive", line=line, column=header[0])
        if values[5] < 0:
            raise InputFileError(path, f"negative BRDF {values[5]:g}", line=line, column=header[5])
        if values[2] != 0:
            raise InputFileError(path, f"incidence azimuth {values[2]:g} deg: only 0 is read (the x-y basis of the "
                                 "file's matrices is converted for incidence in the x-z plane)", line=line, column=header[2])
        for i in range(6, 21):
            check_element(values[i], path, line, header[i])
        check_first_column(values[9], values[13], values[17], path, line, f"{header[9]}, {header[13]}, {header[17]}")
        rows.append(values)
    if not rows:
        raise InputFileError(path, "empty file: header but no data rows", line=header_line)
    data = np.asarray(rows)
    col = {name: data[:, i] for i, name in enumerate(names)}

    theta_i_signed, theta_r_signed = col["thetai"], col["thetar"]
    phi_source = col["phii"] + np.where(theta_i_signed < 0, 180.0, 0.0)
    phi_detector = col["phir"] + np.where(theta_r_signed < 0, 180.0, 0.0)
    dphi = _wrap_deg(phi_source - phi_detector)
    dphi = np.where(dphi == -180.0, 180.0, dphi)

    fr11 = col["fr11"]
    ratios = np.ones((4, 4, len(fr11)))
    for name in _RATIO_NAMES:
        ratios[int(name[1]) - 1, int(name[2]) - 1] = col[name]
    ratios = xy_to_sp(ratios, 180.0 - dphi)
    mueller = ratios * fr11
    stokes = mueller[:, 0, :].copy()
    dop = np.sqrt(ratios[1, 0] ** 2 + ratios[2, 0] ** 2 + ratios[3, 0] ** 2)
    meta = {"source": "NIST Mueller-matrix BRDF", **meta}
    return Dataset(
        theta_i=np.abs(theta_i_signed),
        theta_r=np.abs(theta_r_signed),
        dphi=dphi,
        wavelength_um=col["lambda"],
        dop=dop,
        brdf=fr11,
        stokes=stokes,
        mueller=mueller,
        metadata=meta,
        source=str(path),
    )
