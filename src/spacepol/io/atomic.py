"""Write files atomically: a temporary file in the same folder, renamed into place.

The temporary file is made by ``mkstemp`` (mode 0600); before the rename it gets the mode an
ordinary ``open(..., "w")`` would have given it (0666 less the umask), so outputs follow the
user's umask like any other file they write.
"""

from __future__ import annotations

import json
import os
import tempfile
from contextlib import contextmanager
from pathlib import Path

import numpy as np


def _umask() -> int:
    mask = os.umask(0)  # the only portable way to read it: set and restore at once
    os.umask(mask)
    return mask


def file_mode() -> int:
    """The mode a new regular file gets here: 0666 less the process umask."""
    return 0o666 & ~_umask()


@contextmanager
def atomic_path(path):
    """Yield a temporary path; on success it replaces ``path``, on failure it is removed."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, file_mode())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def jsonable(value):
    """``value`` with numpy arrays and scalars turned into lists and floats, keys into strings: what json.dumps takes."""
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, (np.floating, float)):
        v = float(value)
        return v if np.isfinite(v) else None
    if isinstance(value, (np.integer,)):
        return int(value)
    return value


def write_json(path, data) -> None:
    """Write ``data`` as indented JSON (NumPy values converted), atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(jsonable(data), indent=2) + "\n", encoding="utf-8")


def write_text(path, text: str) -> None:
    """Write ``text`` as UTF-8, atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def save_figure(fig, path, dpi=120) -> None:
    """Write ``fig`` to ``path`` (format from the suffix) atomically."""
    # "tight" keeps labels that reach past the axes (sky-map titles, rotated ticks) on the page; a figure laid out
    # by hand (report.panels) has room for them already, and tight costs a second draw.
    tight = None if getattr(fig, "laid_out_by_hand", False) else "tight"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=Path(path).suffix.lstrip(".") or "png", dpi=dpi, bbox_inches=tight)
