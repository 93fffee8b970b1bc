"""The maximum of the log posterior, found globally: where emcee starts and what screening compares.

Differential evolution searches the prior cube. One region of the index plane needs help: the
dielectric branch k ~ 0 (PTFE, paints, glass) is a sliver of the cube under the default prior
k ~ U(0, 20) (k < 0.05 is 0.25 % of it), and DE started from random points converges on an
absorbing optimum before it looks there. So when k is free, a second DE runs with k pinned at 0
and the better optimum, judged by the full posterior, wins.
"""

from __future__ import annotations

import numpy as np

from .engines.de import run_de
from .objective import NegativeLogPosterior
from .posterior import Posterior
from .priors import Fixed


def _dielectric_branch(posterior: Posterior) -> Posterior | None:
    priors = posterior.priors
    if "k" not in priors.names or priors.priors["k"].bounds[0] > 0:
        return None
    overrides = {name: prior for name, prior in priors.priors.items() if name != "k"}
    overrides["k"] = Fixed(0.0)
    return Posterior(posterior.likelihood, type(priors)(priors.parameters, overrides, where="dielectric branch"),
                     prior_only=posterior.prior_only)


def find_optimum(posterior: Posterior, rng: np.random.Generator, evaluations: int = 4000, seeds=None,
                 popsize: int = 10) -> tuple[float, np.ndarray]:
    """(max log posterior, parameter vector in ``posterior.priors.names`` order)."""
    res = run_de(NegativeLogPosterior(posterior), rng, max_evaluations=evaluations, popsize=popsize, polish=True, seeds=seeds)
    best_value, best = -res.objective, res.best_vector()
    branch = _dielectric_branch(posterior)
    if branch is not None:
        sub_seeds = None if seeds is None else np.delete(np.atleast_2d(seeds), posterior.priors.names.index("k"), axis=1)
        sub = run_de(NegativeLogPosterior(branch), rng, max_evaluations=evaluations, popsize=popsize, polish=True, seeds=sub_seeds)
        values = {**sub.best, "k": 0.0}
        theta = np.array([values[n] for n in posterior.priors.names])
        value = float(posterior.log_prob(theta[None, :])[0])
        if value > best_value:
            best_value, best = value, theta
    return best_value, best
