"""The engine interface: what a sampler or an optimizer implements to be found by name (``infer.engine_registry``)."""

from __future__ import annotations

import inspect
import time

import numpy as np

from ...errors import SpacepolError
from ..engine_result import EngineResult
from ..result import Result

SAMPLER, OPTIMIZER = "sampler", "optimizer"


class Engine:
    """One engine: ``name``, ``kind`` (sampler or optimizer), ``description``, and ``run``. ``variant`` is the text
    after the colon of ``name:variant`` (nlopt's algorithm); ``resumable`` engines keep their chain in the output
    folder so that an interrupted run continues."""

    name: str = ""
    kind: str = SAMPLER
    description: str = ""
    resumable: bool = False
    default: bool = False  # the sampler used where none is named
    variants: tuple[str, ...] = ()  # the variants it accepts (empty: none)

    def __init__(self, variant: str | None = None):
        self.variant = variant

    @classmethod
    def check_variant(cls, variant: str) -> None:
        """A variant (the text after ``name:``) this engine takes; else one line naming the ones it knows."""
        if variant not in cls.variants:
            from ...errors import UnknownNameError

            raise UnknownNameError(f"engine {cls.name}: unknown variant '{variant}' (known: {', '.join(cls.variants) or 'none'})")

    def run(self, problem, rng: np.random.Generator, **options) -> EngineResult:
        """Sample the posterior (a sampler) or minimise the objective (an optimizer)."""
        raise NotImplementedError

    def check_options(self, options: dict) -> None:
        """An option ``run`` does not take is one line naming it (before any work)."""
        parameters = inspect.signature(self.run).parameters
        if any(p.kind is inspect.Parameter.VAR_KEYWORD for p in parameters.values()):
            return
        for key in options:
            if key not in parameters:
                known = [p for p in parameters if p not in ("problem", "posterior", "objective", "rng")]
                raise SpacepolError(f"engine {self.label}: no option '{key}' (it takes {', '.join(known) or 'none'})")

    @property
    def label(self) -> str:
        """The name as a user writes it (``nlopt:LN_SBPLX``)."""
        return self.name + (f":{self.variant}" if self.variant else "")

    def check_chain(self, chain, posterior, seed: int, **options) -> None:
        """A resumable engine: a chain already at ``chain`` must belong to this run (checked before any work)."""

    def result(self, posterior, seed: int = 0, progress: bool = False, chain=None, **options) -> Result:
        """A sampler's Result: ``run`` with a Generator seeded by ``seed``, then the ArviZ groups, diagnostics, PSIS-LOO
        and summary. ``chain``: where a resumable engine keeps its chain (others ignore it)."""
        from ..draws_result import result_of

        start = time.perf_counter()
        rng = np.random.default_rng(seed)
        self.check_options(options)
        if "progress" in inspect.signature(self.run).parameters:
            options = {"progress": progress, **options}
        draws = self.run(posterior, rng, **options)
        _check_draws(self.label, draws, posterior)
        return result_of(posterior, draws, rng, seed, start, engine=self.label)


def _check_draws(label: str, draws, posterior) -> None:
    """What a sampler returned must be draws of every free parameter: one line where it is not."""
    if not isinstance(draws, EngineResult) or draws.samples is None:
        raise SpacepolError(f"engine {label}: run() must return an EngineResult with samples (draws x chains x parameters)")
    samples = np.asarray(draws.samples)
    if samples.ndim != 3 or samples.shape[2] != posterior.ndim or list(draws.names) != list(posterior.names):
        raise SpacepolError(f"engine {label}: samples of shape {samples.shape} for parameters {list(draws.names)}; "
                            f"expected (draws, chains, {posterior.ndim}) for {list(posterior.names)}")
    if not np.all(np.isfinite(samples)):
        raise SpacepolError(f"engine {label}: returned draws that are not finite numbers")
    if draws.log_prob is None or np.shape(draws.log_prob) != samples.shape[:2]:
        raise SpacepolError(f"engine {label}: log_prob must be given per draw and chain, shape {samples.shape[:2]}")


