"""Engines by name, found through one registry: the built-in ones, the ``spacepol.engines`` entry-point group, and a
user's file (``--engine path/to/file.py:Name``).

An engine is a subclass of :class:`Engine` in one file. A sampler's ``run(posterior, rng, **options)`` returns an
:class:`~spacepol.infer.engine_result.EngineResult` with ``samples`` (draws x chains x parameters, in the posterior's
``names`` order) and ``log_prob`` (draws x chains); the library turns it into a
:class:`~spacepol.infer.result.Result` (ArviZ groups, R-hat and ESS, PSIS-LOO, the summary). A sampler that also
estimates the evidence puts ``log_evidence`` and ``log_evidence_error`` into ``info``. An optimizer's
``run(objective, rng, **options)`` returns its best point and search history. ``nlopt:ALGO`` names an engine with a
variant (the engine ``nlopt`` with the algorithm ``ALGO``).
"""

from __future__ import annotations

from ..errors import SpacepolError, UnknownNameError
from ..plugins import PluginRegistry
from .engine_result import EngineResult
from .engines.base import OPTIMIZER, SAMPLER, Engine
from .engines import builtin_engines

class EngineRegistry(PluginRegistry):
    """Engine classes by name: built-ins, the ``spacepol.engines`` entry points, files loaded by ``get``; where each
    plug-in came from in ``sources``."""

    kind, base, group, option = "engine", Engine, "spacepol.engines", "--engine"

    def check_class(self, cls: type[Engine]) -> None:
        """An engine's name has no ':' (that separates a variant) and its kind is a sampler or an optimizer."""
        if ":" in cls.name:
            raise SpacepolError(f"engine class {cls.__name__} needs a 'name' without ':'")
        if cls.kind not in (SAMPLER, OPTIMIZER):
            raise SpacepolError(f"engine {cls.name}: kind '{cls.kind}' is neither '{SAMPLER}' nor '{OPTIMIZER}'")

    def names(self, kind: str | None = None) -> list[str]:
        """Every engine's name (of one ``kind`` when given)."""
        return [n for n, cls in self.classes().items() if kind is None or cls.kind == kind]

    def get(self, name: str, kind: str | None = None) -> Engine:
        """An engine instance for ``name`` (``emcee``, ``nlopt:LN_SBPLX``, ``path/to/file.py:Name``), of ``kind``
        when given; an unknown name, variant or kind is one line listing what there is."""
        if ".py:" in name:
            engine = self.load_file(name)()
        else:
            self.load_entry_points()
            base, _, variant = name.partition(":")
            cls = self._classes.get(base)
            if cls is None:
                raise UnknownNameError(f"unknown engine '{name}' (known: {self._listing(kind)}; or path/to/file.py:Name)")
            if variant:
                cls.check_variant(variant)
            if cls.variants and not variant:
                raise UnknownNameError(f"engine {base} needs a variant, {base}:NAME (NAME in {', '.join(cls.variants)})")
            engine = cls(variant or None)
        if kind is not None and engine.kind != kind:
            raise UnknownNameError(f"engine '{name}' is {_article(engine.kind)} {engine.kind}, not {_article(kind)} {kind} "
                                   f"(the {kind}s: {self._listing(kind)})")
        return engine

    def _listing(self, kind: str | None) -> str:
        return ", ".join(n + (":ALGO" if self._classes[n].variants else "") for n in self.names(kind))


def _article(word: str) -> str:
    return "an" if word[0] in "aeiou" else "a"


engines = EngineRegistry()
for _cls in builtin_engines():
    engines.register(_cls)


def method_names() -> list[str]:
    """Every name ``optimize`` and ``compare`` take: the optimizers (nlopt with each algorithm) and the samplers."""
    names = []
    for name in engines.names():
        cls = engines.classes()[name]
        names += [f"{name}:{v}" for v in cls.variants] if cls.variants else [name]
    return names


def check_method(method: str) -> str:
    """A method name of DESIGN.md (``ga``, ``de``, ``emcee``, ``nlopt:ALGO``, or any registered engine), checked
    before any work."""
    try:
        engines.get(method)
    except UnknownNameError as exc:
        raise UnknownNameError(f"unknown method '{method}' ({exc})") from None
    return method


def optimize(method: str, objective, rng, model_name: str = "", **options) -> EngineResult:
    """Minimise ``objective`` with the optimizer ``method``; its EngineResult (best point, history)."""
    check_method(method)
    return engines.get(method, OPTIMIZER).run(objective, rng, model_name=model_name, **options)


OPTIMIZERS = [m for m in method_names() if engines.get(m).kind == OPTIMIZER]  # the built-in ones, for compare
