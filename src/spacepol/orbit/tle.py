"""Two-line element sets: a file of one or more (optionally named: three-line) sets, each checked by its line
numbers and checksums, so that a damaged file is one line naming the file, the line and what is wrong."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..errors import InputFileError


@dataclass(frozen=True)
class TLE:
    """One element set: the satellite's ``name`` (from a three-line set, else its catalogue number), its two lines
    and where they came from."""

    name: str
    line1: str
    line2: str
    source: str = ""

    @property
    def catalog_number(self) -> int:
        """The NORAD catalogue number (columns 3-7 of line 1)."""
        return int(self.line1[2:7])


def _checksum(line: str) -> int:
    """The TLE checksum of the first 68 columns: the sum of the digits, a minus sign counting 1, modulo 10."""
    return sum(int(c) if c.isdigit() else (1 if c == "-" else 0) for c in line[:68]) % 10


def _check_line(line: str, number: int, path, at: int) -> None:
    if len(line) < 69:
        raise InputFileError(path, f"TLE line {number} has {len(line)} characters, not 69", line=at)
    if not line.startswith(f"{number} "):
        raise InputFileError(path, f"expected TLE line {number} (starting '{number} ')", line=at)
    if not line[68].isdigit() or int(line[68]) != _checksum(line):
        raise InputFileError(path, f"TLE line {number}: checksum {line[68]!r}, the line's digits give {_checksum(line)}",
                             line=at)


def read_tle(path, satellite: str | None = None) -> TLE:
    """The element set of ``satellite`` (a name, or a catalogue number) in the file at ``path``; without a name the
    file must hold exactly one set. Every problem is one :class:`InputFileError` naming the file and line."""
    path = Path(path)
    if not path.is_file():
        raise InputFileError(path, "file not found" if not path.is_dir() else "is a folder, not a TLE file")
    try:
        lines = path.read_text(encoding="utf-8-sig").splitlines()
    except UnicodeDecodeError as exc:
        raise InputFileError(path, f"not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    sets, i = [], 0
    numbered = [(n, line.rstrip()) for n, line in enumerate(lines, start=1) if line.strip()]
    while i < len(numbered):
        at, line = numbered[i]
        name = None
        if not line.startswith("1 "):  # a three-line set: the name first
            name, i = (line[2:] if line.startswith("0 ") else line).strip(), i + 1
            if i >= len(numbered):
                raise InputFileError(path, f"satellite '{name}' has no element lines", line=at)
            at, line = numbered[i]
        if i + 1 >= len(numbered):
            raise InputFileError(path, "TLE line 1 without its line 2", line=at)
        at2, line2 = numbered[i + 1]
        _check_line(line, 1, path, at)
        _check_line(line2, 2, path, at2)
        if line[2:7] != line2[2:7]:
            raise InputFileError(path, f"lines 1 and 2 name different satellites ({line[2:7].strip()} and "
                                       f"{line2[2:7].strip()})", line=at2)
        sets.append(TLE(name or line[2:7].strip(), line, line2, str(path)))
        i += 2
    if not sets:
        raise InputFileError(path, "no element set (two lines starting '1 ' and '2 ')")
    if satellite is None:
        if len(sets) > 1:
            raise InputFileError(path, f"holds {len(sets)} satellites ({', '.join(s.name for s in sets[:5])}"
                                       f"{', ...' if len(sets) > 5 else ''}); choose one with --satellite")
        return sets[0]
    chosen = [s for s in sets if s.name.lower() == satellite.strip().lower() or str(s.catalog_number) == satellite.strip()]
    if not chosen:
        raise InputFileError(path, f"no satellite '{satellite}' (it holds {', '.join(s.name for s in sets[:8])})")
    return chosen[0]
