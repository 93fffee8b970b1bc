"""Where the bundled data lives: the package's ``data`` folder (the repository's top-level ``data/``, linked into the
package so that an installed wheel carries it)."""

from __future__ import annotations

import os
from pathlib import Path


def data_dir() -> Path:
    """The bundled data folder: ``$SPACEPOL_DATA``, else the package's own ``data`` (found through the package's
    location, so an installed wheel and a source checkout alike)."""
    env = os.environ.get("SPACEPOL_DATA")
    if env:
        return Path(env)
    return Path(__file__).resolve().parent / "data"


def bundled(*parts: str) -> Path:
    """A file shipped in the package's data (``bundled("ptfe", "ptfe_mueller_brdf.csv")``); one line when it is
    missing."""
    path = data_dir().joinpath(*parts)
    if not path.exists():
        from .errors import SpacepolError

        raise SpacepolError(f"{path}: bundled data file not found (set SPACEPOL_DATA to the data folder)")
    return path
