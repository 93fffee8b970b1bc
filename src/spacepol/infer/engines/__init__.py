"""The engines, one module each (emcee, Laplace-IS, NUTS, nested sampling, the paper's GA, scipy DE, nlopt), and the
interface they share (``base.Engine``); ``builtin_engines`` finds them, and ``infer.engine_registry`` by name."""

from __future__ import annotations

import importlib
import pkgutil


def builtin_engines() -> tuple[type, ...]:
    """The engine classes the modules of this package define: the default sampler first, then the samplers and the
    optimizers, each in module-name order. Adding a built-in engine is adding one module here."""
    from .base import OPTIMIZER, Engine

    found = []
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        module = importlib.import_module(f"{__name__}.{info.name}")
        found += [obj for obj in vars(module).values() if isinstance(obj, type) and issubclass(obj, Engine)
                  and obj.__module__ == module.__name__ and obj.name]
    return tuple(sorted(found, key=lambda cls: (not cls.default, cls.kind == OPTIMIZER)))
