"""Observables: the measured quantities a likelihood compares with the model, one module each.

The registry finds them: every :class:`Observable` subclass with a name in a module of this package (adding one is
adding one file), the entry points of the group ``spacepol.observables``, and a user's file loaded by ``get`` or
``--observables path/to/file.py:Name``. The file reader, the Dataset, ``--observables``, ``design``'s candidates and
``--noise`` names, and the figures' labels all come from here.
"""

from __future__ import annotations

import importlib
import pkgutil

from ..errors import ParameterError, SpacepolError
from ..plugins import PluginRegistry
from .base import Observable


class ObservableRegistry(PluginRegistry):
    """Observable classes by name (one instance each): the modules of this package, the ``spacepol.observables``
    entry points, and files ``path/to/file.py:Name``; where each plug-in came from in ``sources``."""

    kind, base, group, option = "observable", Observable, "spacepol.observables", "--observables"

    def __init__(self):
        super().__init__()
        self._instances: dict[str, Observable] = {}
        self._files: dict[str, str] = {}  # "path.py:Name" -> the observable it registered (a file is imported once)

    def check_class(self, cls: type[Observable]) -> None:
        """A name that is an identifier, at least one channel, and the file columns and Dataset arrays it reads."""
        if not cls.name.isidentifier():
            raise SpacepolError(f"observable class {cls.__name__}: name '{cls.name}' is not an identifier")
        for attribute in ("channels", "columns", "arrays"):
            if not getattr(cls, attribute):
                raise SpacepolError(f"observable {cls.name}: no {attribute}")
        taken = {a: o.name for o in self._instances.values() if o.name != cls.name for a in (o.name, *o.aliases)}
        clash = next((a for a in (cls.name, *cls.aliases) if a in taken), None)
        if clash is not None:
            raise SpacepolError(f"observable {cls.name}: the name '{clash}' is taken by the observable {taken[clash]}")

    def register(self, cls: type) -> type:
        cls = super().register(cls)
        self._instances[cls.name] = cls()
        return cls

    def every(self) -> list[Observable]:
        """One instance of each registered observable, in listing order."""
        self.load_entry_points()
        return sorted(self._instances.values(), key=lambda o: o.listing_order)

    def names(self) -> list[str]:
        """Every observable's name, in listing order."""
        return [o.name for o in self.every()]

    def get(self, name: str) -> Observable:
        """The observable of that name or alias (``q``, ``u``), or of a file ``path/to/file.py:Name``; one clear
        error for an unknown one."""
        if ".py:" in name:
            if name not in self._files:
                self._files[name] = self.load_file(name).name
            return self._instances[self._files[name]]
        self.load_entry_points()
        for o in self.every():
            if name == o.name or name in o.aliases:
                return o
        aliases = [f"{a} ({o.name})" for o in self.every() for a in o.aliases]
        raise ParameterError(f"unknown observable '{name}' (use {', '.join(self.names())}"
                             + (f"; aliases {', '.join(aliases)}" if aliases else "") + "; or path/to/file.py:Name)")

    def array_names(self) -> set[str]:
        """Every Dataset array an observable keeps."""
        return {a for o in self.every() for a in o.arrays}

    def column_names(self) -> list[str]:
        """Every file column an observable reads, in listing order."""
        return list(dict.fromkeys(c for o in self.every() for c in o.columns + o.optional_columns + o.error_columns))


def _holds(holder: Observable, name: str) -> bool:
    """Whether ``holder``'s numbers include those of the observable ``name`` (declared by either side)."""
    return name in holder.contains or holder.name in registry.get(name).contained_in


def default_for(present: list[str]) -> tuple[list[str], dict[str, str]]:
    """Every present observable except those another present one contains (each measured number is
    counted once): ``(chosen, {left out: the observable holding it})``. BRDF is always independent."""
    chosen = [n for n in present if not any(_holds(registry.get(h), n) for h in present if h != n)]
    left_out = {n: next(h for h in chosen if _holds(registry.get(h), n)) for n in present if n not in chosen}
    return chosen, left_out


def get(name: str) -> Observable:
    """The registered observable of that name (or alias, or ``path/to/file.py:Name``)."""
    return registry.get(name)


def every() -> list[Observable]:
    """Every registered observable (one instance each), in listing order."""
    return registry.every()


registry = ObservableRegistry()
for _module in pkgutil.iter_modules(__path__):
    if _module.name != "base":
        _loaded = importlib.import_module(f"{__name__}.{_module.name}")
        for _obj in vars(_loaded).values():
            if (isinstance(_obj, type) and issubclass(_obj, Observable) and _obj.__module__ == _loaded.__name__
                    and _obj.name):
                registry.register(_obj)

__all__ = ["Observable", "registry", "get", "every", "default_for"]
