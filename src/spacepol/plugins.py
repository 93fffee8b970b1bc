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


class PluginRegistry:
    """Classes by name, of one ``base`` class: the built-ins registered at import, the entry points of ``group``
    (loaded on first use; a broken one is one line), and files ``path/to/file.py:Name`` (``load_file``); where each
    plug-in came from in ``sources``. A subclass names its ``kind`` (for messages), ``base``, ``group`` and
    ``option`` (the command-line option that takes a file), and may add checks in ``check_class``."""

    kind = "plug-in"
    base: type = object
    group = ""
    option = ""

    def __init__(self):
        self._classes: dict[str, type] = {}
        self._entry_points_loaded = False
        self.sources: dict[str, str] = {}  # plug-in name -> where it came from ("path.py:Name", "entry point X")

    def check_class(self, cls: type) -> None:
        """What a class must satisfy besides being a ``base`` subclass with a name (one line where it does not)."""

    def register(self, cls: type) -> type:
        """Add ``cls`` under its ``name`` (a ``base`` subclass; the name not taken by another class: the same file
        loaded again replaces itself); returns the class, so it serves as a decorator."""
        if not (isinstance(cls, type) and issubclass(cls, self.base)):
            raise SpacepolError(f"{cls!r} is not {_article(self.base.__name__)} {self.base.__name__} subclass "
                                f"(use {self.base.__module__}.{self.base.__name__})")
        if not cls.name:
            raise SpacepolError(f"{self.kind} class {cls.__name__} has no 'name'")
        self.check_class(cls)
        known = self._classes.get(cls.name)
        reloaded = known is not None and (known.__module__, known.__qualname__) == (cls.__module__, cls.__qualname__)
        if known is not None and known is not cls and not reloaded:
            raise SpacepolError(f"{self.kind} name '{cls.name}' is already registered by {known.__module__}.{known.__name__}")
        self._classes[cls.name] = cls
        return cls

    def load_entry_points(self) -> None:
        """Register the entry points of ``group`` (once)."""
        if self._entry_points_loaded:
            return
        self._entry_points_loaded = True
        from importlib.metadata import entry_points

        for ep in entry_points(group=self.group):
            try:
                self.sources[self.register(ep.load()).name] = f"entry point {ep.name}"
            except Exception as exc:  # a broken plug-in is named, not hidden
                raise SpacepolError(f"entry point '{ep.name}' ({ep.value}) of group {self.group}: {exc}") from exc

    def load_file(self, spec: str) -> type:
        """Load ``path/to/file.py:Name`` and register it."""
        obj, source = load_attribute(spec, self.option, f"spacepol_user_{self.kind}")
        cls = self.register(obj)
        self.sources[cls.name] = source
        return cls

    def classes(self) -> dict[str, type]:
        """Every registered class by name (entry points loaded first), in registration order."""
        self.load_entry_points()
        return dict(self._classes)


def _article(word: str) -> str:
    return "an" if word[0].lower() in "aeiou" else "a"
