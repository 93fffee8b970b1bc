"""A satellite's measured light curve: the CSV of ``invert-mcmc synth-pass`` and ``invert-mcmc lightcurve``.

Columns (DESIGN.md): ``time_utc`` (ISO 8601 with its offset), then any of three observables, each with its 1-sigma
error: ``flux`` and ``flux_err`` (the target's photon flux at the aperture in the camera's band, photons m^-2 s^-1),
``dolp`` and ``dolp_err`` (degree of linear polarization), ``aop_deg`` and ``aop_err_deg`` (angle of polarization
in the observer's sky basis: from the horizontal towards the local vertical's projection, degrees in (-90, 90]).
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..skylight.sun import parse_time

OBSERVABLES = {"flux": "flux_err", "dolp": "dolp_err", "aop_deg": "aop_err_deg"}
COLUMNS = ("time_utc", *(name for pair in OBSERVABLES.items() for name in pair))


@dataclass
class LightCurve:
    """A light curve at N times: ``times_utc`` (aware datetimes in UTC) and, per observable measured, its values and
    1-sigma errors ((N,) arrays; None where the file has no such column); ``source`` names where it came from."""

    times_utc: list[datetime]
    flux: np.ndarray | None = None
    flux_err: np.ndarray | None = None
    dolp: np.ndarray | None = None
    dolp_err: np.ndarray | None = None
    aop_deg: np.ndarray | None = None
    aop_err_deg: np.ndarray | None = None
    source: str = "light curve"

    @property
    def observables(self) -> list[str]:
        """The observables measured, in the file's order of ``OBSERVABLES`` (flux, dolp, aop_deg)."""
        return [name for name in OBSERVABLES if getattr(self, name) is not None]

    def __len__(self) -> int:
        return len(self.times_utc)

    def rows(self) -> list[dict]:
        """One record per time: time_utc (ISO 8601, Z) and each observable and error measured."""
        out = []
        for j, t in enumerate(self.times_utc):
            row = {"time_utc": t.strftime("%Y-%m-%dT%H:%M:%S.%fZ")}
            for name, err in OBSERVABLES.items():
                if getattr(self, name) is not None:
                    row[name], row[err] = float(getattr(self, name)[j]), float(getattr(self, err)[j])
            out.append(row)
        return out


def write_light_curve(path, curve: LightCurve) -> None:
    """``curve`` as the light-curve CSV (only the observables it holds), written whole or not at all."""
    from .atomic import write_text

    columns = ["time_utc", *(c for name in curve.observables for c in (name, OBSERVABLES[name]))]
    lines = [",".join(columns)]
    for row in curve.rows():
        lines.append(",".join(row["time_utc"] if c == "time_utc" else repr(row[c]) for c in columns))
    write_text(Path(path), "\n".join(lines) + "\n")


def read_light_curve(path) -> LightCurve:
    """The light-curve CSV at ``path``: one line naming the file, row and column for a missing or unknown column, an
    observable without its error column, a time without its UTC offset, a value that is not a finite number, or an
    error that is not > 0."""
    path = Path(path)
    if not path.is_file():
        raise ParameterError(f"{path}: file not found")
    try:
        with path.open(newline="", encoding="utf-8") as handle:
            reader = csv.DictReader(handle)
            header = [h.strip() for h in (reader.fieldnames or [])]
            records = list(reader)
    except (UnicodeDecodeError, csv.Error) as exc:
        raise ParameterError(f"{path}: not a CSV file ({exc})") from None
    _check_header(path, header)
    if not records:
        raise ParameterError(f"{path}: no rows after the header")
    present = [name for name in OBSERVABLES if name in header]
    times, values = [], {c: [] for name in present for c in (name, OBSERVABLES[name])}
    for line, record in enumerate(records, start=2):
        record = {(k or "").strip(): (v or "").strip() for k, v in record.items()}
        try:
            times.append(parse_time(record["time_utc"]))
        except ParameterError as exc:
            raise ParameterError(f"{path}, line {line}, time_utc: {str(exc).split(': ', 1)[-1]}") from None
        for column in values:
            values[column].append(_number(path, line, column, record.get(column, "")))
    arrays = {c: np.array(v) for c, v in values.items()}
    for name in present:
        bad = np.flatnonzero(~(arrays[OBSERVABLES[name]] > 0))
        if bad.size:
            raise ParameterError(f"{path}, line {bad[0] + 2}, {OBSERVABLES[name]}: {arrays[OBSERVABLES[name]][bad[0]]:g} "
                                 "is not an error > 0")
    if len(set(times)) != len(times):
        raise ParameterError(f"{path}: two rows share a time_utc")
    return LightCurve(times, **arrays, source=str(path))


def _check_header(path: Path, header: list[str]) -> None:
    unknown = sorted(set(header) - set(COLUMNS))
    if unknown:
        raise ParameterError(f"{path}: unknown column {', '.join(unknown)} (known: {', '.join(COLUMNS)})")
    if "time_utc" not in header:
        raise ParameterError(f"{path}: no time_utc column")
    for name, err in OBSERVABLES.items():
        if (name in header) != (err in header):
            raise ParameterError(f"{path}: {name} needs its error column {err} and the other way round")
    if not any(name in header for name in OBSERVABLES):
        raise ParameterError(f"{path}: no observable (flux, dolp or aop_deg, each with its error column)")


def _number(path: Path, line: int, column: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ParameterError(f"{path}, line {line}, {column}: '{text}' is not a number") from None
    if not np.isfinite(value):
        raise ParameterError(f"{path}, line {line}, {column}: '{text}' is not a finite number")
    return value
