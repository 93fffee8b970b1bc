"""nlopt's global algorithms on the prior cube."""

from __future__ import annotations

import time

import nlopt
import numpy as np

from ...errors import UnknownNameError
from ..engine_result import EngineResult, History
from .base import OPTIMIZER, Engine

NLOPT_ALGORITHMS = ["GN_CRS2_LM", "GN_ISRES", "GN_DIRECT_L", "GN_ESCH", "GN_MLSL_LDS"]


def check_algorithm(algorithm: str) -> int:
    """nlopt's code for a global algorithm name; UnknownNameError otherwise."""
    code = getattr(nlopt, algorithm, None) if algorithm.isidentifier() else None
    if not isinstance(code, int) or not algorithm.startswith("G"):
        raise UnknownNameError(f"unknown nlopt global algorithm '{algorithm}' (try {', '.join(NLOPT_ALGORITHMS)})")
    return code


def run_nlopt(objective, algorithm: str, rng: np.random.Generator, model_name: str = "",
              max_evaluations: int = 20000, ftol_rel: float = 1e-10, seed: int | None = None) -> EngineResult:
    """An nlopt algorithm on the prior cube from a random start, at most ``max_evaluations``; its EngineResult with the
    search history."""
    code = check_algorithm(algorithm)
    start = time.perf_counter()
    priors, ndim = objective.priors, objective.priors.ndim
    history = History()
    nlopt.srand(int(rng.integers(2**31)))
    opt = nlopt.opt(code, ndim)
    opt.set_lower_bounds([0.0] * ndim)
    opt.set_upper_bounds([1.0] * ndim)
    if algorithm.startswith("GN_MLSL") or algorithm.startswith("G_MLSL"):
        local = nlopt.opt(nlopt.LN_BOBYQA, ndim)
        local.set_ftol_rel(1e-8)
        local.set_maxeval(max(200, max_evaluations // 50))
        opt.set_local_optimizer(local)
    opt.set_maxeval(max_evaluations)
    opt.set_ftol_rel(ftol_rel)

    def f(u, grad):
        theta = priors.rescale(np.clip(np.asarray(u), 0, 1)[None, :])
        value = float(objective(theta)[0])
        history.record(theta, [value])
        return value

    opt.set_min_objective(f)
    x0 = rng.uniform(0.2, 0.8, ndim)
    try:
        opt.optimize(x0)
        status = opt.last_optimize_result()
    except (nlopt.RoundoffLimited, RuntimeError) as exc:  # keep the best point found so far
        status = f"stopped: {type(exc).__name__}"
    return history.to_result(f"nlopt:{algorithm}", objective, model_name, time.perf_counter() - start, seed,
                             {"status": str(status)})


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
        return run_nlopt(objective, self.variant, rng, **options)
