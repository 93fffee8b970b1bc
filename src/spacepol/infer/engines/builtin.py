"""The engines that ship with spacepol, each a small :class:`~.base.Engine` over its module: samplers ``emcee``
(default), ``laplace`` (Laplace approximation corrected by importance sampling), ``nuts`` (numpyro) and ``nested``
(nautilus, with the evidence); optimizers
``ga`` (the paper's), ``de`` (scipy) and ``nlopt:ALGO``."""

from __future__ import annotations

import sys

import numpy as np

from .base import OPTIMIZER, SAMPLER, Engine
from .nlopt_engine import NLOPT_ALGORITHMS, check_algorithm


class Emcee(Engine):
    """emcee's affine-invariant ensemble in the logit space of the priors, run until R-hat <= 1.01, ESS >= 400 and
    50 autocorrelation times (or ``max_steps``); its chain is kept in the output folder, so an interrupted run
    continues."""

    name, kind, resumable = "emcee", SAMPLER, True
    description = "affine-invariant ensemble sampler (emcee), resumable; the default"

    def run(self, posterior, rng, walkers: int | None = None, max_steps: int = 20000, tau_multiple: float = 50.0,
            progress: bool = False):
        """emcee's draws (``engines.emcee_sampler.sample_emcee``)."""
        from .emcee_sampler import sample_emcee

        return sample_emcee(posterior, rng, walkers=walkers, max_steps=max_steps, tau_multiple=tau_multiple,
                            progress=progress, model_name=posterior.likelihood.model.name)

    def result(self, posterior, seed: int = 0, progress: bool = False, chain=None, **options):
        """``inversion.invert``: the start-point search, the chain (kept in ``chain`` when given), the Result."""
        from ..inversion import invert

        self.check_options(options)
        return invert(posterior, seed=seed, backend_path=chain, progress=progress, **options)

    def check_chain(self, chain, posterior, seed: int, walkers: int | None = None, **_) -> None:
        """A chain already in ``chain`` must be readable and belong to this run (before any work)."""
        from ..inversion import check_resumable

        check_resumable(chain, posterior, walkers, seed)


class Laplace(Engine):
    """A Laplace approximation at the posterior's optimum, corrected by importance sampling; where its checks refuse
    it (Pareto k, effective draws, width, the walkers' spread), emcee samples instead and the Result says so
    (``summary["diagnostics"]["engine"]`` names what ran, ``summary["laplace_refused"]`` why)."""

    name, kind, resumable = "laplace", SAMPLER, True  # its emcee fallback keeps its chain, so an interrupted run continues
    description = "Laplace approximation at the optimum corrected by importance sampling; emcee where it cannot be trusted"

    def run(self, posterior, rng, draws: int = 2000, progress: bool = False):
        """Equally weighted draws resampled from the importance-weighted ones (emcee's where refused)."""
        return self.result(posterior, int(rng.integers(2**31)), draws=draws, progress=progress).draws

    def result(self, posterior, seed: int = 0, progress: bool = False, chain=None, draws: int = 2000, **options):
        """``inversion.laplace_fit`` at the optimum the start-point search finds; where its checks refuse the
        approximation, one line saying which (the refusal's figures) and ``inversion.invert`` from that optimum."""
        from ..inversion import invert, laplace_fit
        from ..optimum import find_optimum

        self.check_options(options)
        _, centre = find_optimum(posterior, np.random.default_rng(seed))
        result, refusal = laplace_fit(posterior, centre, seed=seed, draws=draws)
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


class Nuts(Engine):
    """numpyro's NUTS on the compiled, differentiable likelihood in the logit space, dense mass matrix, several
    chains, run in blocks until R-hat <= 1.01 and ESS >= 400 (or ``max_draws``)."""

    name, kind = "nuts", SAMPLER
    description = "No-U-Turn sampler (numpyro) on the differentiable likelihood"

    def run(self, posterior, rng, chains: int = 4, warmup: int = 500, draws: int = 500, max_draws: int = 8000,
            target_accept: float = 0.8, progress: bool = False):
        """NUTS draws (``engines.nuts.sample_nuts``)."""
        from .nuts import sample_nuts

        return sample_nuts(posterior, rng, chains=chains, warmup=warmup, draws=draws, max_draws=max_draws,
                           target_accept=target_accept, progress=progress, model_name=posterior.likelihood.model.name)


class Nested(Engine):
    """Nested sampling (nautilus): the posterior and the evidence ln Z with its error from independent replicates
    (``engines.nested``)."""

    name, kind = "nested", SAMPLER
    description = "nested sampling (nautilus): posterior and log evidence with its error"

    def run(self, posterior, rng, live: int = 500, replicates: int = 3, networks: int = 1, effective_draws: int = 4000,
            progress: bool = False):
        """Draws and ln Z (``engines.nested.sample_nested``)."""
        from .nested import missed_mode, sample_nested

        draws = sample_nested(posterior, rng, live=live, replicates=replicates, networks=networks,
                              effective_draws=effective_draws, progress=progress)
        missed = missed_mode(posterior, draws, rng)
        if missed is not None:
            draws.info["missed_mode"] = missed
            if progress:
                print(f"  {missed['finding']}", file=sys.stderr, flush=True)
        return draws


class GeneticAlgorithm(Engine):
    """The paper's genetic algorithm on the prior cube (``engines.ga.run_ga``)."""

    name, kind = "ga", OPTIMIZER
    description = "the paper's genetic algorithm (binary genes, crossover, mutation)"

    def run(self, objective, rng, **options):
        """The GA's best point and search history."""
        from .ga import run_ga

        return run_ga(objective, rng, **options)


class DifferentialEvolution(Engine):
    """scipy's differential evolution on the prior cube, polished by L-BFGS-B (``engines.de.run_de``)."""

    name, kind = "de", OPTIMIZER
    description = "differential evolution (scipy), polished"

    def run(self, objective, rng, **options):
        """DE's best point and search history."""
        from .de import run_de

        return run_de(objective, rng, **options)


class Nlopt(Engine):
    """An nlopt algorithm on the prior cube (``nlopt:LN_SBPLX`` and the others in ``variants``)."""

    name, kind = "nlopt", OPTIMIZER
    description = "an nlopt algorithm, nlopt:ALGO"
    variants = tuple(NLOPT_ALGORITHMS)  # the ones compare runs; any global (G*) algorithm of nlopt is taken

    @classmethod
    def check_variant(cls, variant: str) -> None:
        """Any of nlopt's global algorithms (``GN_...``, ``GD_...``)."""
        check_algorithm(variant)

    def run(self, objective, rng, **options):
        """The algorithm's best point and search history."""
        from .nlopt_engine import run_nlopt

        return run_nlopt(objective, self.variant, rng, **options)


BUILTIN_ENGINES = (Emcee, Laplace, Nuts, Nested, GeneticAlgorithm, DifferentialEvolution, Nlopt)
