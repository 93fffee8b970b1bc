"""Where the bundled data lives (the repository's top-level ``data/`` folder)."""

from __future__ import annotations

import os
from pathlib import Path


def data_dir() -> Path:
    """The bundled data folder: ``$SPACEPOL_DATA`` or ``data/`` beside ``src/``."""
    env = os.environ.get("SPACEPOL_DATA")
    if env:
        return Path(env)
    return Path(__file__).resolve().parents[2] / "data"


def bundled(*parts: str) -> Path:
    """A file shipped in the package's data (``bundled("ptfe", "ptfe_mueller_brdf.csv")``); one line when it is
    missing."""
    path = data_dir().joinpath(*parts)
    if not path.exists():
        from .errors import SpacepolError

        raise SpacepolError(f"{path}: bundled data file not found (set SPACEPOL_DATA to the data folder)")
    return path
