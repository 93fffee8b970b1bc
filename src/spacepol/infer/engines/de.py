"""scipy's differential evolution on the prior cube."""

from __future__ import annotations

import time

import numpy as np
from scipy.optimize import differential_evolution

from .. import local_search
from ..engine_result import EngineResult, History
from .base import OPTIMIZER, Engine


def run_de(objective, rng: np.random.Generator, model_name: str = "", max_evaluations: int = 30000,
           popsize: int = 15, tol: float = 1e-8, seed: int | None = None, polish: bool = True,
           seeds=None, polish_ftol: float | None = None) -> EngineResult:
    """``seeds``: parameter vectors (S, D) placed in the initial population (DE is elitist, so the
    result is never worse than the best of them); ``polish_ftol``: the closing polish's stopping tolerance
    (``local_search._lbfgsb``)."""
    start = time.perf_counter()
    priors, ndim = objective.priors, objective.priors.ndim
    history = History()

    def f(u):
        # scipy's vectorised mode passes (D, S)
        theta = priors.rescale(np.clip(np.asarray(u).T, 0.0, 1.0))
        values = objective(theta)
        history.record(theta, values)
        return values

    maxiter = max(1, max_evaluations // (popsize * ndim) - 1)
    init = "latinhypercube"
    de_rng = np.random.default_rng(rng.integers(2**63))
    if seeds is not None:
        from scipy.stats import qmc

        init = qmc.LatinHypercube(d=ndim, rng=de_rng).random(popsize * ndim)
        seeds_u = priors.to_unit(np.atleast_2d(seeds))[: len(init) - 1]
        init[: len(seeds_u)] = np.clip(seeds_u, 0.0, 1.0)
    res = differential_evolution(
        f, bounds=[(0.0, 1.0)] * ndim, maxiter=maxiter, popsize=popsize, tol=tol,
        rng=de_rng, vectorized=True, updating="deferred", polish=False, init=init,
    )
    best_u = np.clip(res.x, 0, 1)
    if polish:
        _, best_u = local_search.polish(lambda rows: f(rows.T), best_u, ftol=polish_ftol)
    return history.to_result("de", objective, model_name, time.perf_counter() - start, seed,
                             {"message": str(res.message), "iterations": int(res.nit)})


class DifferentialEvolution(Engine):
    """scipy's differential evolution on the prior cube, polished by L-BFGS-B (``engines.de.run_de``)."""

    name, kind = "de", OPTIMIZER
    description = "differential evolution (scipy), polished"

    def run(self, objective, rng, **options):
        """DE's best point and search history."""
        return run_de(objective, rng, **options)
