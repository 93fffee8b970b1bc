"""Public face of the effect machinery: ``Effect``, ``effect``, ``Parameter`` and the ``registry``."""

from .builtin_effects import BUILTIN_EFFECTS, PRESETS
from .effect import Context, Effect, effect
from .parameter import Parameter
from .registry import registry

__all__ = ["BUILTIN_EFFECTS", "PRESETS", "Context", "Effect", "effect", "Parameter", "registry"]
