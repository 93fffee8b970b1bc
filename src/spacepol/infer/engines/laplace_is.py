"""The ``laplace`` engine: a Laplace approximation at the posterior's optimum corrected by importance sampling
(``infer.laplace``), with emcee where its checks refuse it; the default posterior of ``diagnose``'s candidate fits."""

from __future__ import annotations

import sys

import numpy as np

from .base import SAMPLER, Engine


class Laplace(Engine):
    """A Laplace approximation at the posterior's optimum, corrected by importance sampling; where its checks refuse
    it (Pareto k, effective draws, width, the walkers' spread), emcee samples instead and the Result says so
    (``summary["diagnostics"]["engine"]`` names what ran, ``summary["laplace_refused"]`` why)."""

    name, kind, resumable = "laplace", SAMPLER, True  # its emcee fallback keeps its chain, so an interrupted run continues
    description = "Laplace approximation at the optimum corrected by importance sampling; emcee where it cannot be trusted"

    def approximate(self, posterior, centre, seed: int = 0, draws: int = 2000):
        """(Result, "") where the approximation at ``centre`` (an optimum) is trusted, else (None, why not in words):
        ``inversion.laplace_fit``, no fallback."""
        from ..inversion import laplace_fit

        return laplace_fit(posterior, centre, seed=seed, draws=draws)

    def run(self, posterior, rng, draws: int = 2000, progress: bool = False):
        """Equally weighted draws resampled from the importance-weighted ones (emcee's where refused)."""
        return self.result(posterior, int(rng.integers(2**31)), draws=draws, progress=progress).draws

    def result(self, posterior, seed: int = 0, progress: bool = False, chain=None, draws: int = 2000, **options):
        """``inversion.laplace_fit`` at the optimum the start-point search finds; where its checks refuse the
        approximation, one line saying which (the refusal's figures) and ``inversion.invert`` from that optimum."""
        from ..inversion import invert
        from ..optimum import find_optimum

        self.check_options(options)
        _, centre = find_optimum(posterior, np.random.default_rng(seed))
        result, refusal = self.approximate(posterior, centre, seed=seed, draws=draws)
        if result is not None:
            return result
        if progress:
            print(f"  the Laplace approximation cannot be trusted here ({refusal}): sampling with emcee",
                  file=sys.stderr, flush=True)
        result = invert(posterior, seed=seed, progress=progress, centre=centre, backend_path=chain)
        result.summary["laplace_refused"] = refusal
        return result

    def check_chain(self, chain, posterior, seed: int, **_) -> None:
        """A chain its emcee fallback left in ``chain`` must belong to this run (before any work)."""
        from ..inversion import check_resumable

        check_resumable(chain, posterior, None, seed)
