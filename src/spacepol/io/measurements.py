"""Reading and writing measurement files (DESIGN.md, "Measurement files", fixed).

CSV, UTF-8, optional leading ``# key: value`` metadata lines, one header row, data rows,
angles in degrees.  Required: ``theta_i``, ``theta_r`` and an observable (``dop``, ``brdf`` or
``s0,s1,s2``), unless the file is only a geometry (``forward``).  NIST's Mueller-matrix BRDF
layout is recognised by its header and handed to :mod:`spacepol.io.nist`.

Every problem is reported as one :class:`InputFileError` naming file, line and column.
"""

from __future__ import annotations

import csv
import io as _io
from pathlib import Path

import numpy as np

from ..errors import InputFileError
from .cells import check_first_column, check_mueller_element, is_blank_row, parse_number
from .dataset import GEOMETRY_COLUMNS, KNOWN_COLUMNS, MUELLER_COLUMNS, OBSERVABLE_COLUMNS, Dataset
from .nist import is_nist_header, read_nist_rows

__all__ = ["Dataset", "GEOMETRY_COLUMNS", "KNOWN_COLUMNS", "MUELLER_COLUMNS", "OBSERVABLE_COLUMNS", "read_measurements",
           "write_table"]

def _parse_metadata(lines, path):
    meta, first_data = {}, 0
    for number, line in enumerate(lines, start=1):
        stripped = line.strip()
        if not stripped:
            first_data = number
            continue
        if not stripped.startswith("#"):
            break
        first_data = number
        body = stripped.lstrip("#").strip()
        if not body:
            continue
        key, sep, value = body.partition(":")
        if not sep:
            raise InputFileError(path, f"metadata line '{stripped}' is not '# key: value'", line=number)
        meta[key.strip()] = value.strip()
    return meta, first_data


def read_measurements(path, require_observable: bool = True) -> Dataset:
    """Read a spacepol CSV or a NIST Mueller BRDF file."""
    path = Path(path)
    if path.is_dir():
        raise InputFileError(path, "is a folder, not a measurement file")
    if not path.is_file():
        raise InputFileError(path, "file not found")
    try:
        text = path.read_text(encoding="utf-8-sig")  # "-sig": spreadsheets save "CSV UTF-8" with a byte-order mark
    except UnicodeDecodeError as exc:
        raise InputFileError(path, f"not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    lines = text.splitlines()
    meta, skip = _parse_metadata(lines, path)
    if skip >= len(lines):
        raise InputFileError(path, "empty file: no header row")
    header_line = skip + 1
    header = [h.strip() for h in next(csv.reader([lines[skip]]))]

    if is_nist_header(header):
        return read_nist_rows(path, header, lines[skip + 1 :], header_line, meta)

    for column in header:
        if column not in KNOWN_COLUMNS:
            raise InputFileError(
                path, f"unknown column '{column}' (known: {', '.join(KNOWN_COLUMNS)})", line=header_line
            )
    if len(set(header)) != len(header):
        raise InputFileError(path, "a column name appears twice in the header", line=header_line)
    for required in ("theta_i", "theta_r"):
        if required not in header:
            raise InputFileError(path, f"missing required column '{required}'", line=header_line)
    stokes_cols = [c for c in ("s0", "s1", "s2") if c in header]
    if stokes_cols and len(stokes_cols) < 3:
        raise InputFileError(path, "Stokes data need all of s0, s1, s2", line=header_line)
    _check_mueller_header(header, path, header_line)
    has_observable = "dop" in header or "brdf" in header or len(stokes_cols) == 3 or "m12" in header
    if require_observable and not has_observable:
        raise InputFileError(path, "no observable column: need dop, brdf, s0,s1,s2 or m12 ... m44", line=header_line)
    for err, base in (("dop_err", "dop"), ("brdf_err", "brdf"), ("aop_err", "aop")):
        if err in header and base not in header:
            raise InputFileError(path, f"column '{err}' without '{base}'", line=header_line)

    columns: dict[str, list[float]] = {c: [] for c in header}
    reader = csv.reader(_io.StringIO("\n".join(lines[skip + 1 :])))
    for offset, row in enumerate(reader, start=1):
        line = header_line + offset
        if is_blank_row(row, path, line):
            continue
        if len(row) != len(header):
            raise InputFileError(path, f"{len(row)} fields, header has {len(header)}", line=line)
        values = {}
        for column, cell in zip(header, row):
            values[column] = parse_number(cell.strip(), path, line, column)
            _check_value(values[column], column, path, line)
            columns[column].append(values[column])
        if "s0" in values:
            _check_stokes(values, path, line)
        if "m21" in values:
            check_first_column(values["m21"], values["m31"], values["m41"], path, line, "m21, m31, m41")
    if not columns["theta_i"]:
        raise InputFileError(path, "empty file: header but no data rows", line=header_line)

    arrays = {c: np.asarray(v) for c, v in columns.items()}
    n = len(arrays["theta_i"])
    wavelength = arrays.get("wavelength_um")
    if wavelength is None and "wavelength_um" in meta:
        wl = parse_number(meta["wavelength_um"], path, None, "wavelength_um metadata")
        if wl <= 0:
            raise InputFileError(path, f"metadata wavelength_um {wl:g} um must be positive")
        wavelength = np.full(n, wl)
    stokes = None
    if len(stokes_cols) == 3:
        s3 = arrays.get("s3", np.zeros(n))
        stokes = np.array([arrays["s0"], arrays["s1"], arrays["s2"], s3])
    mueller, mueller_err = _mueller(arrays, n)
    return Dataset(
        theta_i=arrays["theta_i"],
        theta_r=arrays["theta_r"],
        dphi=arrays.get("dphi", np.full(n, 180.0)),
        wavelength_um=wavelength,
        dop=arrays.get("dop"),
        dop_err=arrays.get("dop_err"),
        brdf=arrays.get("brdf"),
        brdf_err=arrays.get("brdf_err"),
        stokes=stokes,
        aop=arrays.get("aop"),
        aop_err=arrays.get("aop_err"),
        mueller=mueller,
        mueller_err=mueller_err,
        metadata=meta,
        source=str(path),
    )


def _check_mueller_header(header, path, line):
    """All 15 normalised elements or none; errors as m_err, or per element for all 15."""
    given = [m for m in MUELLER_COLUMNS if m in header]
    if given and len(given) < 15:
        missing = [m for m in MUELLER_COLUMNS if m not in header]
        raise InputFileError(path, f"Mueller data need all 15 elements m12 ... m44; missing {', '.join(missing)}", line=line)
    errors = [f"{m}_err" for m in MUELLER_COLUMNS if f"{m}_err" in header]
    if (errors or "m_err" in header) and not given:
        raise InputFileError(path, f"column '{(errors or ['m_err'])[0]}' without the Mueller elements m12 ... m44", line=line)
    if errors and len(errors) < 15 and "m_err" not in header:
        missing = [f"{m}_err" for m in MUELLER_COLUMNS if f"{m}_err" not in header]
        raise InputFileError(path, f"per-element Mueller errors need all 15 columns (or one m_err for the rest); "
                                   f"missing {', '.join(missing)}", line=line)


def _mueller(arrays, n):
    """(4, 4, N) Mueller matrix (M_11 = BRDF, or 1 without one) and its errors, or (None, None)."""
    if "m12" not in arrays:
        return None, None
    m11 = arrays.get("brdf", np.ones(n))
    mueller = np.empty((4, 4, n))
    errors = np.full((4, 4, n), np.nan)
    for name in ("m11",) + MUELLER_COLUMNS:
        i, j = int(name[1]) - 1, int(name[2]) - 1
        mueller[i, j] = m11 * (1.0 if name == "m11" else arrays[name])
        if name != "m11":
            err = arrays.get(f"{name}_err", arrays.get("m_err"))
            if err is not None:
                errors[i, j] = err
    has_errors = "m_err" in arrays or "m12_err" in arrays
    return mueller, (errors if has_errors else None)


def _check_stokes(values: dict, path, line) -> None:
    """A Stokes row must be a possible polarization state: its polarized part no larger than s0 (a degree of
    polarization in [0, 1], as the dop column's check)."""
    polarized = float(np.sqrt(values["s1"] ** 2 + values["s2"] ** 2 + values.get("s3", 0.0) ** 2))
    if polarized > values["s0"]:
        parts = "s1, s2, s3" if "s3" in values else "s1, s2"
        raise InputFileError(path, f"Stokes vector with |({parts})| = {polarized:g} above s0 = {values['s0']:g} "
                                   "(a degree of polarization above 1)", line=line, column="s1")


def _check_value(value, column, path, line):
    if column in ("theta_i", "theta_r") and abs(value) >= 90:
        raise InputFileError(path, f"angle {value:g} deg: |angle| must be below 90", line=line, column=column)
    if column == "dop" and not 0 <= value <= 1:
        raise InputFileError(path, f"DOP {value:g} outside [0, 1]", line=line, column=column)
    if column.endswith("_err") and value < 0:
        raise InputFileError(path, f"negative uncertainty {value:g}", line=line, column=column)
    if column == "wavelength_um" and value <= 0:
        raise InputFileError(path, f"wavelength {value:g} um must be positive", line=line, column=column)
    if column in ("brdf", "s0") and value < 0:
        raise InputFileError(path, f"negative intensity {value:g}", line=line, column=column)
    if column in MUELLER_COLUMNS:
        check_mueller_element(value, path, line, column)


def write_table(path, columns: dict, metadata: dict | None = None) -> None:
    """Write a CSV with ``# key: value`` metadata, atomically (a temp file renamed into place)."""
    from .atomic import atomic_path

    names = list(columns)
    data = np.column_stack([np.asarray(columns[c], dtype=float) for c in names])
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8", newline="") as fh:
        for key, value in (metadata or {}).items():
            fh.write(f"# {key}: {value}\n")
        fh.write(",".join(names) + "\n")
        for row in data:
            fh.write(",".join(repr(float(v)) for v in row) + "\n")
