"""Read a TOML input file (priors, scenarios) with one-line errors naming the file."""

from __future__ import annotations

import tomllib
from pathlib import Path

from ..errors import SpacepolError


def read_toml(path, what: str) -> dict:
    """The tables of a TOML file; a missing or malformed file is one line naming it and ``what`` it should hold."""
    path = Path(path)
    if not path.is_file():
        raise SpacepolError(f"{path}: {what} file not found")
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise SpacepolError(f"{path}: not valid TOML ({exc})") from None
