"""Loading a user's plug-in from a file: ``path/to/file.py:Name`` -> the object ``Name`` that file defines.

Effects (``--effect``) and engines (``--engine``) are found this way besides their entry-point groups. Every failure
is one line naming the option, the file and, for an error raised while importing it, the line in that file.
"""

from __future__ import annotations

import importlib.util
import traceback
from pathlib import Path

from .errors import SpacepolError


def load_attribute(spec: str, option: str, prefix: str = "spacepol_user_plugin"):
    """The object ``Name`` defined by the file of ``spec`` (``path/to/file.py:Name``), imported as a fresh module
    ``{prefix}_{stem}``. ``option`` names where the spec came from (``--effect``) in error messages."""
    path_text, sep, attr = spec.rpartition(":")
    if not sep or not attr or not path_text:
        raise SpacepolError(f"{option} '{spec}': expected path/to/file.py:Name")
    path = Path(path_text)
    if not path.is_file():
        raise SpacepolError(f"{option} '{spec}': file {path} not found")
    module_spec = importlib.util.spec_from_file_location(f"{prefix}_{path.stem}", path)
    module = importlib.util.module_from_spec(module_spec)
    try:
        module_spec.loader.exec_module(module)
    except SystemExit as exc:
        raise SpacepolError(f"{option} '{spec}': importing {path} called sys.exit({exc.code!r})") from None
    except Exception as exc:
        here = path.resolve()
        line = next((n for f, n in traceback.walk_tb(exc.__traceback__) if Path(f.f_code.co_filename).resolve() == here),
                    None)
        at = f" (line {line})" if line else ""
        raise SpacepolError(f"{option} '{spec}': importing {path} failed{at}: {type(exc).__name__}: {exc}") from None
    if not hasattr(module, attr):
        raise SpacepolError(f"{option} '{spec}': {path} defines no '{attr}'")
    return getattr(module, attr), f"{path.resolve()}:{attr}"
