"""Effect registry: the built-ins (one module each in ``physics/effects/``), the ``spacepol.effects`` entry-point
group, and ``file.py:Name``."""

from __future__ import annotations

import importlib
import pkgutil

from ..errors import UnknownNameError
from ..plugins import PluginRegistry
from .effect import Effect

PRESETS = {"paper": "specular+shadowing+body", "torrance-sparrow": "specular+shadowing"}


def builtin_effects() -> tuple[type[Effect], ...]:
    """The effect classes the modules of ``spacepol.physics.effects`` define, module by module in name order: adding
    a built-in effect is adding one module there."""
    from . import effects as package

    found = []
    for info in sorted(pkgutil.iter_modules(package.__path__), key=lambda m: m.name):
        module = importlib.import_module(f"{package.__name__}.{info.name}")
        found += [obj for obj in vars(module).values() if isinstance(obj, type) and issubclass(obj, Effect)
                  and obj.__module__ == module.__name__ and obj.name]
    return tuple(found)


class Registry(PluginRegistry):
    """Effects by name: the built-in ones, plug-in files (``--effect FILE.py:Name``) and entry points (group
    ``spacepol.effects``), with where each came from (``sources``)."""

    kind, base, group, option = "effect", Effect, "spacepol.effects", "--effect"

    def names(self) -> list[str]:
        """Every registered effect's name (entry points loaded first), in registration order."""
        return list(self.classes())

    def get(self, name: str) -> type[Effect]:
        """The effect class of this name; an unknown name is one line listing the known ones."""
        self.load_entry_points()
        try:
            return self._classes[name]
        except KeyError:
            raise UnknownNameError(
                f"unknown effect '{name}' (known: {', '.join(self._classes)}; presets: {', '.join(PRESETS)})"
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


BUILTIN_EFFECTS = builtin_effects()
registry = Registry()
for _cls in BUILTIN_EFFECTS:
    registry.register(_cls)
