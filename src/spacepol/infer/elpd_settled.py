"""When a chain run for one number, its ELPD-LOO, may stop before the posterior has converged: when the ELPD-LOO
of its first and second halves agree.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from .diagnostics import PARETO_K_LIMIT, psis_loo, relative_efficiency
from .inference_data import batched

# the two halves' ELPD-LOO agree within this many log units: half of the smallest difference diagnose calls
# significant (``criteria.MIN_DELTA_ELPD``, 4)
TOLERANCE = 2.0
FIRST_STEP = 2000  # no earlier (a chain's first thousand steps on a ridge are still its burn-in)
EVERY = 1000  # steps between checks (each evaluates up to 2 x DRAWS_PER_HALF draws' pointwise log likelihood)
DRAWS_PER_HALF = 1000
# and neither half's PSIS-LOO unreliable (Pareto k > 0.7) for more than this share of the observations: a chain on
# the oxide-layer ridge with 3.6 % such observations reported an ELPD-LOO 14 below the long chains'; its halves agreed
BAD_K_SHARE = 0.01


def elpd_loo_of(posterior, chain: np.ndarray, draws: int = DRAWS_PER_HALF) -> tuple[float, float]:
    """(ELPD-LOO, the share of observations whose Pareto k exceeds 0.7) of a stretch of chain (steps, walkers, D) of
    ``posterior``, as a Result's PSIS-LOO computes them (``diagnostics.loo``: the walkers' relative efficiency),
    from its steps thinned evenly to at most ``draws`` draws."""
    import xarray as xr

    steps, walkers, ndim = chain.shape
    kept = chain[:: max(1, int(np.ceil(steps * walkers / draws)))]
    flat = kept.reshape(-1, ndim)
    ll = batched(posterior.log_prob_pointwise, flat, posterior.likelihood.batch_sets).T
    reff = 1.0
    if walkers > 1:
        dataset = xr.Dataset({f"p{j}": (("chain", "draw"), chain[:, :, j].T) for j in range(ndim)})
        reff = relative_efficiency(dataset, len(flat))
    pointwise, k, _ = psis_loo(ll, reff)
    return float(pointwise.sum()), float(np.mean(k > PARETO_K_LIMIT))


def settled(posterior, tolerance: float = TOLERANCE, first_step: int = FIRST_STEP, every: int = EVERY,
            draws_per_half: int = DRAWS_PER_HALF, bad_k_share: float = BAD_K_SHARE) -> Callable[[int, np.ndarray], bool]:
    """``sample_emcee``'s ``enough``: given the step count and the chain after burn-in in the declared parameters
    (steps, walkers, D), True where the ELPD-LOO of its first and second halves (``elpd_loo_of``, each from at most
    ``draws_per_half`` draws) differ by at most ``tolerance`` and neither half has more than ``bad_k_share`` of its
    observations' Pareto k above 0.7; checked from ``first_step`` on, every ``every`` steps. Records each check as
    (step, first half's ELPD, second half's, the larger bad-k share) in ``checks``."""
    checks: list[tuple[int, float, float, float]] = []

    def enough(step: int, chain: np.ndarray) -> bool:
        if step < first_step or step % every or len(chain) < 4:
            return False
        (first, bad_first), (second, bad_second) = (elpd_loo_of(posterior, half, draws_per_half)
                                                    for half in (chain[: len(chain) // 2], chain[len(chain) // 2 :]))
        checks.append((step, first, second, max(bad_first, bad_second)))
        return abs(first - second) <= tolerance and max(bad_first, bad_second) <= bad_k_share

    enough.checks = checks
    return enough
