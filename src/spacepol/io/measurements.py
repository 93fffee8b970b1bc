"""Reading and writing measurement files (DESIGN.md, "Measurement files", fixed).

CSV, UTF-8, optional leading ``# key: value`` metadata lines, one header row, data rows,
angles in degrees.  Required: ``theta_i``, ``theta_r`` and an observable's columns (``dop``, ``brdf``,
``s0,s1,s2``, ``m12 ... m44`` or any registered observable's), unless the file is only a geometry (``forward``).  NIST's Mueller-matrix BRDF
layout is recognised by its header and handed to :mod:`spacepol.io.nist`.

Every problem is reported as one :class:`InputFileError` naming file, line and column.
"""

from __future__ import annotations

import csv
import io as _io
from pathlib import Path

import numpy as np

from ..errors import InputFileError
from ..observables import registry
from .cells import is_blank_row, parse_number
from .dataset import GEOMETRY_COLUMNS, Dataset
from .nist import is_nist_header, read_nist_rows

__all__ = ["Dataset", "GEOMETRY_COLUMNS", "known_columns", "read_measurements", "write_table"]

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
    """Read a spacepol CSV or a NIST Mueller BRDF file. The columns besides the geometry, their checks and the
    Dataset arrays they become are the registered observables' (``spacepol.observables``)."""
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

    known = known_columns()
    for column in header:
        if column not in known:
            raise InputFileError(path, f"unknown column '{column}' (known: {', '.join(known)})", line=header_line)
    if len(set(header)) != len(header):
        raise InputFileError(path, "a column name appears twice in the header", line=header_line)
    for required in ("theta_i", "theta_r"):
        if required not in header:
            raise InputFileError(path, f"missing required column '{required}'", line=header_line)
    observables = registry.every()
    for o in observables:
        o.check_header(header, path, header_line)
    present = [o for o in observables if o.in_header(header)]
    if require_observable and not present:
        needs = ", ".join(",".join(o.columns) if len(o.columns) <= 3 else f"{o.columns[0]} ... {o.columns[-1]}"
                          for o in observables)
        raise InputFileError(path, f"no observable column: need one of {needs}", line=header_line)
    owner = {c: o for o in reversed(present) for c in o.columns + o.optional_columns + o.error_columns if c in header}

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
            if column in owner:
                owner[column].check_value(column, values[column], path, line)
            else:
                _check_geometry(values[column], column, path, line)
            columns[column].append(values[column])
        for o in present:
            o.check_row(values, path, line)
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
    data = {}
    for o in present:
        data.update(o.read(arrays, n))
    return Dataset(arrays["theta_i"], arrays["theta_r"], arrays.get("dphi", np.full(n, 180.0)), wavelength,
                   metadata=meta, source=str(path), **data)


def known_columns() -> list[str]:
    """Every column a measurement file may have: the geometry's and the registered observables'."""
    return list(GEOMETRY_COLUMNS) + registry.column_names()


def _check_geometry(value, column, path, line):
    if column in ("theta_i", "theta_r") and abs(value) >= 90:
        raise InputFileError(path, f"angle {value:g} deg: |angle| must be below 90", line=line, column=column)
    if column == "wavelength_um" and value <= 0:
        raise InputFileError(path, f"wavelength {value:g} um must be positive", line=line, column=column)


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
