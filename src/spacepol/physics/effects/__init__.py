"""The built-in effects, one module each (found by ``physics.registry``), and the public face of the effect machinery:
``Effect``, ``effect``, ``Parameter``, ``Context``, the ``registry``, ``BUILTIN_EFFECTS`` and ``PRESETS``."""

from ..effect import Context, Effect, effect
from ..parameter import Parameter

__all__ = ["BUILTIN_EFFECTS", "PRESETS", "Context", "Effect", "effect", "Parameter", "registry"]


def __getattr__(name):
    # the registry imports this package's modules to find the built-ins: its names are read from it on first use
    if name in ("registry", "BUILTIN_EFFECTS", "PRESETS"):
        import importlib

        return getattr(importlib.import_module("..registry", __package__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
