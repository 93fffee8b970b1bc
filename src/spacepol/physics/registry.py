"""Effect registry: built-ins, the ``spacepol.effects`` entry-point group, and ``file.py:Name``."""

from __future__ import annotations

import inspect
from importlib.metadata import entry_points

from ..errors import SpacepolError, UnknownNameError
from ..plugins import load_attribute
from .builtin_effects import BUILTIN_EFFECTS, PRESETS
from .effect import Effect


class Registry:
    """Effects by name: the built-in ones, plug-in files (``--effect FILE.py:Name``) and entry points (group
    ``spacepol.effects``), with where each came from (``sources``)."""

    def __init__(self):
        self._effects: dict[str, type[Effect]] = {}
        self._entry_points_loaded = False
        self.sources: dict[str, str] = {}  # plug-in effect name -> where it came from ("path.py:Name", "entry point X")

    def register(self, cls: type[Effect]) -> type[Effect]:
        """Add an effect class under its ``name`` (an Effect subclass with a name not taken by another class); returns
        the class, so it serves as a decorator."""
        if not (inspect.isclass(cls) and issubclass(cls, Effect)):
            raise SpacepolError(f"{cls!r} is not an Effect subclass (use spacepol.physics.effect.Effect or @effect)")
        if not cls.name:
            raise SpacepolError(f"effect class {cls.__name__} has no 'name'")
        known = self._effects.get(cls.name)
        reloaded = known is not None and (known.__module__, known.__qualname__) == (cls.__module__, cls.__qualname__)
        if known is not None and known is not cls and not reloaded:  # the same file loaded again replaces itself
            raise SpacepolError(f"effect name '{cls.name}' is already registered by {known.__module__}.{known.__name__}")
        self._effects[cls.name] = cls
        return cls

    def _load_entry_points(self):
        if self._entry_points_loaded:
            return
        self._entry_points_loaded = True
        for ep in entry_points(group="spacepol.effects"):
            try:
                self.sources[self.register(ep.load()).name] = f"entry point {ep.name}"
            except Exception as exc:  # a broken plug-in must not hide the built-ins
                raise SpacepolError(f"entry point '{ep.name}' ({ep.value}) of group spacepol.effects: {exc}") from exc

    def load_file(self, spec: str) -> type[Effect]:
        """Load ``path/to/file.py:ClassName`` and register it."""
        obj, source = load_attribute(spec, "--effect", "spacepol_user_effect")
        cls = self.register(obj)
        self.sources[cls.name] = source
        return cls

    def names(self) -> list[str]:
        """Every registered effect's name (entry points loaded first), in registration order."""
        self._load_entry_points()
        return list(self._effects)

    def get(self, name: str) -> type[Effect]:
        """The effect class of this name; an unknown name is one line listing the known ones."""
        self._load_entry_points()
        try:
            return self._effects[name]
        except KeyError:
            raise UnknownNameError(
                f"unknown effect '{name}' (known: {', '.join(self._effects)}; presets: {', '.join(PRESETS)})"
            ) from None

    def expand(self, spec: str) -> list[str]:
        """'paper+polarized_diffuse' -> ['specular', 'shadowing', 'body', 'polarized_diffuse']."""
        names: list[str] = []
        for token in spec.split("+"):
            token = token.strip()
            if not token:
                raise UnknownNameError(f"model '{spec}': empty effect name between '+' signs")
            for name in PRESETS.get(token, token).split("+"):
                if name in names:
                    raise UnknownNameError(f"model '{spec}': effect '{name}' appears twice")
                names.append(name)
        return names


registry = Registry()
for _cls in BUILTIN_EFFECTS:
    registry.register(_cls)
