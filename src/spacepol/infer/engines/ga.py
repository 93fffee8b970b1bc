"""The paper's genetic algorithm (section 2.3), as printed, with the ERRATA's readings.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import time

import numpy as np

from ..engine_result import EngineResult, History
from .base import OPTIMIZER, Engine


def _decode(chromosomes, bits):
    weights = 2.0 ** np.arange(bits)[::-1]
    return (chromosomes @ weights) / (2**bits - 1)  # (pop, D) in [0, 1]


def run_ga(objective, rng: np.random.Generator, model_name: str = "", bits: int = 16, population: int = 100,
           p_crossover: float = 0.02, p_mutation: float = 0.02, max_generations: int = 100,
           tolerance: float = 1e-3, n_replace: int = 20, seed: int | None = None) -> EngineResult:
    """The paper's genetic algorithm (binary genes of ``bits`` per parameter over the prior cube, crossover, mutation,
    the worst ``n_replace`` replaced per generation), stopped when the best changes by less than ``tolerance``
    or after ``max_generations``; its EngineResult with the search history."""
    start = time.perf_counter()
    priors, ndim = objective.priors, objective.priors.ndim
    history = History()
    pop = rng.integers(0, 2, size=(population, ndim, bits)).astype(float)

    def evaluate(chromosomes):
        theta = priors.rescale(_decode(chromosomes, bits))
        values = objective(theta)
        history.record(theta, values)
        return values

    fitness = evaluate(pop)
    generations, stop_reason = 0, "max_generations"
    for generations in range(1, max_generations + 1):
        if abs(fitness.min() - fitness.mean()) < tolerance:
            stop_reason = "best and mean fitness within tolerance"
            break
        order = np.argsort(fitness)
        survivors = pop[order[: population - n_replace]]
        refill = survivors[rng.integers(0, len(survivors), n_replace)]
        pop = np.concatenate([survivors, refill]).copy()
        elite = pop[0].copy()
        _crossover(pop, rng, p_crossover)
        _mutate(pop, rng, p_mutation)
        pop[0] = elite
        fitness = evaluate(pop)

    return history.to_result("ga", objective, model_name, time.perf_counter() - start, seed,
                             {"generations": generations, "stop_reason": stop_reason, "bits": bits})


def _crossover(pop, rng, probability):
    population, ndim, bits = pop.shape
    order = rng.permutation(population)
    flat = pop.reshape(population, ndim * bits)
    for a, b in zip(order[0::2], order[1::2]):
        if rng.uniform() >= probability:
            continue
        kind = rng.integers(3)
        if kind == 0:  # single point
            cut = rng.integers(1, ndim * bits)
            mask = np.arange(ndim * bits) >= cut
        elif kind == 1:  # multi-point (two cuts)
            lo, hi = np.sort(rng.choice(np.arange(1, ndim * bits), 2, replace=False))
            mask = (np.arange(ndim * bits) >= lo) & (np.arange(ndim * bits) < hi)
        else:  # uniform
            mask = rng.uniform(size=ndim * bits) < 0.5
        flat[a, mask], flat[b, mask] = flat[b, mask].copy(), flat[a, mask].copy()


def _mutate(pop, rng, probability):
    population, ndim, bits = pop.shape
    hits = np.argwhere(rng.uniform(size=(population, ndim)) < probability)
    for i, j in hits:
        kind = rng.integers(3)
        if kind == 0:  # uniform: a new random value in range
            pop[i, j] = rng.integers(0, 2, bits)
        elif kind == 1:  # boundary: the range's minimum or maximum
            pop[i, j] = float(rng.integers(0, 2))
        else:  # basic position: flip one bit
            k = rng.integers(bits)
            pop[i, j, k] = 1.0 - pop[i, j, k]


class GeneticAlgorithm(Engine):
    """The paper's genetic algorithm on the prior cube (``engines.ga.run_ga``)."""

    name, kind = "ga", OPTIMIZER
    description = "the paper's genetic algorithm (binary genes, crossover, mutation)"

    def run(self, objective, rng, **options):
        """The GA's best point and search history."""
        return run_ga(objective, rng, **options)
