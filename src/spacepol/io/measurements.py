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
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..errors import InputFileError
from ..physics.geometry import Geometry

GEOMETRY_COLUMNS = ("theta_i", "theta_r", "dphi", "wavelength_um")
MUELLER_COLUMNS = tuple(f"m{i}{j}" for i in range(1, 5) for j in range(1, 5))[1:]  # m12 ... m44 = M_ij / M_11
OBSERVABLE_COLUMNS = (("dop", "dop_err", "brdf", "brdf_err", "s0", "s1", "s2", "s3", "aop", "aop_err")
                      + MUELLER_COLUMNS + ("m_err",) + tuple(f"{m}_err" for m in MUELLER_COLUMNS))
KNOWN_COLUMNS = GEOMETRY_COLUMNS + OBSERVABLE_COLUMNS


@dataclass
class Dataset:
    """Measurements at N geometries.  Absent observables are ``None``; angles in degrees."""

    theta_i: np.ndarray
    theta_r: np.ndarray
    dphi: np.ndarray
    wavelength_um: np.ndarray | None = None
    dop: np.ndarray | None = None
    dop_err: np.ndarray | None = None
    brdf: np.ndarray | None = None  # sr^-1
    brdf_err: np.ndarray | None = None
    stokes: np.ndarray | None = None  # (4, N): s0..s3 for unpolarized incidence (s3 may be 0)
    aop: np.ndarray | None = None  # deg
    aop_err: np.ndarray | None = None
    mueller: np.ndarray | None = None  # (4, 4, N) BRDF Mueller matrix (sr^-1; M_11 = 1 when no BRDF was measured)
    mueller_err: np.ndarray | None = None  # (4, 4, N) 1-sigma errors of the normalised elements m_ij (M_11's unused)
    metadata: dict = field(default_factory=dict)
    source: str = ""

    def __len__(self):
        return len(self.theta_i)

    # Normalised Stokes parameters q = S1/S0, u = S2/S0 (s-polarized light has q > 0).
    @property
    def q(self):
        return None if self.stokes is None else self.stokes[1] / np.where(self.stokes[0] > 0, self.stokes[0], np.inf)

    @property
    def u(self):
        return None if self.stokes is None else self.stokes[2] / np.where(self.stokes[0] > 0, self.stokes[0], np.inf)

    q_err = None
    u_err = None

    @property
    def geometry(self) -> Geometry:
        if not hasattr(self, "_geometry"):
            self._geometry = Geometry(self.theta_i, self.theta_r, self.dphi, self.wavelength_um)
        return self._geometry

    @property
    def observables(self) -> list[str]:
        names = [n for n in ("dop", "brdf", "aop") if getattr(self, n) is not None]
        if self.stokes is not None:
            names.append("stokes")
        if self.mueller is not None:
            names.append("mueller")
        return names

    def select(self, mask) -> "Dataset":
        """A subset of the rows (boolean mask or indices)."""
        idx = np.arange(len(self))[mask]
        changes = {}
        for name in ("theta_i", "theta_r", "dphi", "wavelength_um", "dop", "dop_err", "brdf", "brdf_err", "aop", "aop_err"):
            value = getattr(self, name)
            changes[name] = None if value is None else value[idx]
        changes["stokes"] = None if self.stokes is None else self.stokes[:, idx]
        changes["mueller"] = None if self.mueller is None else self.mueller[:, :, idx]
        changes["mueller_err"] = None if self.mueller_err is None else self.mueller_err[:, :, idx]
        return replace(self, **changes)

    def in_plane(self, tolerance_deg: float = 1e-6) -> "Dataset":
        """Rows in the plane of incidence: dphi = 0 (retro side) or 180 deg (specular side)."""
        off = np.abs(np.sin(np.radians(self.dphi)))
        return self.select(off < np.sin(np.radians(tolerance_deg)) + 1e-12)

    def at_wavelengths(self, wavelengths_um, tolerance_um: float = 1e-4) -> "Dataset":
        """The rows at any of ``wavelengths_um`` (each must be present)."""
        keep = np.zeros(len(self), bool)
        for w in wavelengths_um:
            keep |= self._rows_at(w, tolerance_um)
        return self.select(keep)

    def _rows_at(self, wavelength_um: float, tolerance_um: float):
        """Boolean mask of the rows at ``wavelength_um``; absent -> one line naming the wavelengths there are."""
        if self.wavelength_um is None:
            raise InputFileError(self.source, "has no wavelength to select on")
        keep = np.abs(self.wavelength_um - wavelength_um) < tolerance_um
        if not keep.any():
            have = ", ".join(f"{w:g}" for w in np.unique(self.wavelength_um))
            raise InputFileError(self.source, f"no rows at wavelength {wavelength_um:g} um (have {have})")
        return keep

    def at_wavelength(self, wavelength_um: float, tolerance_um: float = 1e-4) -> "Dataset":
        out = self.select(self._rows_at(wavelength_um, tolerance_um))
        out.metadata = {**self.metadata, "wavelength_um": wavelength_um}
        return out


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


def _number(text, path, line, column):
    try:
        value = float(text)
    except ValueError:
        shown = text if text.strip() else "(empty)"
        raise InputFileError(path, f"'{shown}' is not a number", line=line, column=column) from None
    if not np.isfinite(value):
        raise InputFileError(path, f"'{text}' is not a finite number", line=line, column=column)
    return value


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

    from .nist import is_nist_header, read_nist_rows

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
        if is_blank_row(row):
            continue
        if all(not cell.strip() for cell in row):
            raise InputFileError(path, "a row of empty fields (only separators): no values", line=line)
        if len(row) != len(header):
            raise InputFileError(path, f"{len(row)} fields, header has {len(header)}", line=line)
        values = {}
        for column, cell in zip(header, row):
            values[column] = _number(cell.strip(), path, line, column)
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
        wl = _number(meta["wavelength_um"], path, None, "wavelength_um metadata")
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


def is_blank_row(row: list[str]) -> bool:
    """Whether a parsed CSV row is a blank line (no separator, at most whitespace): skipped. A row of separators
    alone is not blank: its fields are empty, which is an error."""
    return len(row) <= 1 and all(not cell.strip() for cell in row)


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


def check_mueller_element(value, path, line, column):
    if abs(value) > 1:
        raise InputFileError(path, f"normalised Mueller element {value:g} outside [-1, 1]", line=line, column=column)


def check_first_column(m21, m31, m41, path, line, column):
    """The state unpolarized light leaves in (m21, m31, m41): its degree of polarization cannot exceed 1."""
    dop = float(np.sqrt(m21**2 + m31**2 + m41**2))
    if dop > 1:
        raise InputFileError(path, f"m21, m31, m41 imply DOP {dop:.4g} > 1 for unpolarized light", line=line, column=column)


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
