"""The batch manifest: a CSV with one row per data set.

Columns ``id`` and ``data`` (a path relative to the manifest) are required; ``model``, ``observables``,
``prior`` (relative to the manifest), ``seed`` and ``wavelength_um`` (one value, a comma list in quotes, or
``all``) are optional and default to those of ``invert-mcmc run``. A malformed manifest is one error naming
the line; a data file that is missing or broken is not: that set fails and the others run.
"""

from __future__ import annotations

import csv
import re
from dataclasses import asdict, dataclass
from pathlib import Path

from ..errors import InputFileError

REQUIRED = ("id", "data")
OPTIONAL = ("model", "observables", "prior", "seed", "wavelength_um")
_ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,99}$")  # it names a folder: no separators, no leading dot


@dataclass(frozen=True)
class BatchJob:
    """One data set's inversion: what ``invert-mcmc run`` would be given."""

    id: str
    data: str  # absolute path
    model: str = "paper"
    observables: str | None = None
    prior: str | None = None  # absolute path
    seed: int = 0
    wavelength_um: str | None = None

    def settings(self) -> dict:
        """What decides the result (a finished set whose settings changed is run again)."""
        return asdict(self)


def read_manifest(path) -> list[BatchJob]:
    """The jobs of a manifest CSV (``id``, ``data`` and the optional columns), checked row by row: one line naming the
    row and column that is wrong."""
    path = Path(path)
    if not path.is_file():
        raise InputFileError(path, "is a folder, not a manifest" if path.is_dir() else "file not found")
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputFileError(path, f"not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    rows = [row for row in csv.reader(text.splitlines()) if row and not row[0].lstrip().startswith("#")]
    if not rows:
        raise InputFileError(path, "empty manifest: no header row (id,data[,model,observables,prior,seed,wavelength_um])")
    header = [h.strip() for h in rows[0]]
    for name in header:
        if name not in REQUIRED + OPTIONAL:
            raise InputFileError(path, f"unknown column '{name}' (known: {', '.join(REQUIRED + OPTIONAL)})", line=1)
    for name in REQUIRED:
        if name not in header:
            raise InputFileError(path, f"no '{name}' column (the manifest needs id and data)", line=1)
    if len(set(header)) != len(header):
        raise InputFileError(path, "a column name appears twice in the header", line=1)
    if len(rows) == 1:
        raise InputFileError(path, "no data sets (only a header)")
    jobs, seen = [], {}
    for line, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise InputFileError(path, f"{len(row)} fields where the header has {len(header)}", line=line)
        fields = {name: value.strip() for name, value in zip(header, row)}
        jobs.append(_job(path, line, fields))
        if jobs[-1].id in seen:
            raise InputFileError(path, f"id '{jobs[-1].id}' also on line {seen[jobs[-1].id]} (each set needs its own id)", line=line)
        seen[jobs[-1].id] = line
    return jobs


def _job(path: Path, line: int, fields: dict) -> BatchJob:
    ident = fields["id"]
    if not _ID.match(ident):
        raise InputFileError(path, f"id '{ident}' must be letters, digits, '.', '_' or '-' (it names the set's folder)",
                             line=line, column="id")
    if not fields["data"]:
        raise InputFileError(path, "empty data path", line=line, column="data")
    here = path.resolve().parent
    seed = fields.get("seed") or "0"
    try:
        seed_value = int(seed)
        if seed_value < 0:
            raise ValueError
    except ValueError:
        raise InputFileError(path, f"seed '{seed}' is not an integer >= 0", line=line, column="seed") from None
    prior = fields.get("prior") or None
    return BatchJob(id=ident, data=str(here / fields["data"]), model=fields.get("model") or "paper",
                    observables=fields.get("observables") or None, prior=str(here / prior) if prior else None,
                    seed=seed_value, wavelength_um=fields.get("wavelength_um") or None)
