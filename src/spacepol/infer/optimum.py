"""The maximum of the log posterior, found globally: where emcee starts and what screening compares.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import numpy as np

from . import local_search
from .differentiable import cube_objective
from .engines.de import run_de
from .objective import NegativeLogPosterior
from .posterior import PinnedPosterior, Posterior
from ..priors import Fixed
from .profiled import ProfiledPosterior


def _branches(posterior: Posterior):
    """The posterior restricted to each ``branch`` an effect of the model declares (parameter values
    inside the prior that a global search would miss): the dielectric k = 0 of ``specular`` ..."""
    priors = posterior.priors
    for effect in posterior.likelihood.model.effects:
        for branch in effect.branches:
            # over several wavelengths a pinned parameter (k = 0) pins each copy (k@0.633, ...)
            pinned = {n: v for name, v in branch.items() for n in priors.names if n == name or n.startswith(f"{name}@")}
            if not pinned or any(not priors.priors[n].bounds[0] <= v <= priors.priors[n].bounds[1] for n, v in pinned.items()):
                continue
            overrides = {name: prior for name, prior in priors.priors.items() if name not in pinned}
            overrides.update({n: Fixed(float(v)) for n, v in pinned.items()})
            sub = type(priors)(priors.parameters, overrides, where=f"{effect.name} branch {pinned}")
            yield pinned, PinnedPosterior(posterior, sub, pinned)


def find_optimum(posterior: Posterior, rng: np.random.Generator, evaluations: int = 4000, seeds=None,
                 popsize: int = 10, branch_multistart: bool = False) -> tuple[float, np.ndarray]:
    """(max log posterior, parameter vector in ``posterior.priors.names`` order): the best of ``candidates``."""
    return max(candidates(posterior, rng, evaluations, seeds, popsize, branch_multistart), key=lambda c: c[0])


def candidates(posterior: Posterior, rng: np.random.Generator, evaluations: int = 4000, seeds=None, popsize: int = 10,
               branch_multistart: bool = False, multistart_too: bool = True,
               polish_ftol: float | None = None) -> list[tuple[float, np.ndarray]]:
    """The optimum each search found, as (log posterior, full parameter vector): DE on the prior cube, DE on each
    effect's branch (and a multistart there, with ``branch_multistart``), the multistart on the cube (unless not
    ``multistart_too``); ``polish_ftol``: the DE polishes' stopping tolerance."""
    res = run_de(NegativeLogPosterior(posterior), rng, max_evaluations=evaluations, popsize=popsize, polish=True, seeds=seeds,
                 polish_ftol=polish_ftol)
    found = [(-float(res.objective), res.best_vector())]
    for pinned, branch in _branches(posterior):
        keep = [j for j, n in enumerate(posterior.priors.names) if n not in pinned]
        sub_seeds = None if seeds is None else np.atleast_2d(seeds)[:, keep]
        sub = run_de(NegativeLogPosterior(branch), rng, max_evaluations=evaluations, popsize=popsize, polish=True, seeds=sub_seeds,
                     polish_ftol=polish_ftol)
        searched = [sub.best_vector()]
        if branch_multistart:
            searched.append(multistart(branch, rng, gradient=None)[1])
        for vector in searched:
            values = {**dict(zip(branch.priors.names, vector)), **pinned}
            theta = np.array([values[n] for n in posterior.priors.names])
            found.append((float(posterior.log_prob(theta[None, :])[0]), theta))
    if multistart_too:
        found.append(multistart(posterior, rng, gradient=None))
    return found


# screening's polishes (its own and DE's) stop where a step changes the log posterior by < 1e-7 of its value, a
# fraction of scipy's default's time. A screening gain is then a lower bound by a few units; it only ranks the
# candidates, and the leaders are searched again and refitted with the default tolerance
SCREEN_FTOL = 1e-7


def screen_optimum(posterior: Posterior, rng: np.random.Generator, starts, new: list[int], evaluations: int = 4000,
                   points: int = 512, polished: int = 3, popsize: int = 10) -> tuple[float, np.ndarray]:
    """A changed model's maximum near a known one, for screening: (max log posterior, parameter vector).
    ``starts`` (S, D): the base model's optimum with the change's own parameters at a few values (row 0 first);
    ``new``: the columns of those parameters. A Sobol scan over the ``new`` columns alone (``points`` rows, the rest
    at row 0), the best ``polished`` distinct rows of scan and starts polished by L-BFGS-B on every parameter, then
    DE on the cube and on each effect's branch seeded with those optima (elitist: never worse than them). The
    global multistart of ``find_optimum`` is left to the leaders (``diagnose``): it was 30-60 % of a candidate's
    screening, and a change's gain shows near the model it changes. The scan over the new parameters is what keeps
    the multistart's use for a thin film: its thickness's comb of interference orders."""
    from scipy.stats import qmc

    priors = posterior.priors
    starts = np.atleast_2d(np.asarray(starts, float))
    rows = starts
    if new and points:
        unit = np.repeat(priors.to_unit(starts[:1]), points, axis=0)
        unit[:, new] = qmc.Sobol(len(new), rng=np.random.default_rng(rng.integers(2**63))).random(points)
        rows = np.concatenate([starts, priors.rescale(unit)])
    batch = posterior.likelihood.batch_sets
    values = np.concatenate([posterior.log_prob(rows[i : i + batch]) for i in range(0, len(rows), batch)])
    order = [i for i in np.argsort(-values) if np.isfinite(values[i])]
    chosen = []
    for i in order:  # distinct rows: the scan may hold the same optimum's basin many times over
        if not any(np.allclose(rows[i], rows[j]) for j in chosen):
            chosen.append(i)
        if len(chosen) == polished:
            break
    found = [polish_posterior(posterior, rows[i], ftol=SCREEN_FTOL) for i in chosen] or [(float(values[0]), starts[0])]
    seeds = np.array([theta for _, theta in sorted(found, key=lambda c: -c[0])] + list(starts))
    found += candidates(posterior, rng, evaluations, seeds, popsize, multistart_too=False, polish_ftol=SCREEN_FTOL)
    return max(found, key=lambda c: c[0])


def find_optimum_profiled(posterior: Posterior, rng: np.random.Generator, evaluations: int = 4000) -> tuple[float, np.ndarray]:
    """The searches of ``candidates`` (with a multistart on each branch) over the model's parameters, the noise
    levels at their conditional maximum (``profiled``); then the full posterior polished from each search's optimum:
    (max log posterior, parameter vector). A branch's optimum is polished too, though its profiled value is below
    the cube's: on PTFE (four wavelengths) the dielectric branch's polish ends ~6,000 log units above the cube's.
    Without a level to profile, ``find_optimum`` itself."""
    profiled = ProfiledPosterior.of(posterior)
    if profiled is None:
        return find_optimum(posterior, rng, evaluations, branch_multistart=True)
    found = candidates(profiled, rng, evaluations, branch_multistart=True)
    return max((polish_posterior(posterior, profiled.complete(theta)[0]) for _, theta in found), key=lambda c: c[0])


def find_optimum_on_every(posterior: Posterior, every: int, rng: np.random.Generator,
                          evaluations: int = 4000) -> tuple[float, np.ndarray]:
    """``find_optimum_profiled`` on every ``every``-th row of the data (same model and priors), its optimum then
    polished on all rows: (max log posterior, parameter vector). Where the rows are many more than the optimum's
    position needs (PTFE at four wavelengths: 7,296 geometries x 16 numbers), the global search's cost falls with
    the rows; ``every`` <= 1 is ``find_optimum_profiled`` itself."""
    if every <= 1:
        return find_optimum_profiled(posterior, rng, evaluations)
    coarse = posterior.on_rows(np.arange(0, len(posterior.likelihood.data), every))
    _, theta = find_optimum_profiled(coarse, rng, evaluations)
    return polish_posterior(posterior, theta)


def polish_posterior(posterior: Posterior, theta, ftol: float | None = None) -> tuple[float, np.ndarray]:
    """The local maximum of the log posterior nearest ``theta`` (L-BFGS-B in the prior cube): (value, vector);
    ``theta`` itself where the polish does not improve on it. ``ftol``: L-BFGS-B's relative stopping change."""
    objective, priors = NegativeLogPosterior(posterior), posterior.priors
    theta = np.asarray(theta, float)
    start_value = float(posterior.log_prob(theta[None, :])[0])
    negative, u = local_search.polish(lambda u: objective(priors.rescale(np.clip(u, 0.0, 1.0))), priors.to_unit(theta[None, :])[0],
                                      ftol=ftol)
    polished = priors.rescale(u[None, :])[0]
    value = -negative if negative < 1e300 else -np.inf  # NegativeLogPosterior's stand-in for a non-finite value
    return (value, polished) if value > start_value or not np.isfinite(start_value) else (start_value, theta)


# ``gradient=None``: above this many numbers x (parameters + 1) a finite-difference gradient (one batch of D + 1
# rows) costs more than the exact reverse-mode one (``benchmarks/optimum_speed.py``: 84-168 numbers, D 5-7: the JAX gradient
# multistart 0.4-0.7x as fast, its L-BFGS iterating longer; PTFE, 29,184 numbers, D 10: 1.3x faster; PTFE at four
# wavelengths, every 8th row, 14,592 numbers, D 23, profiled: 3.7x faster with its compilation, the same maximum).
# Speed is not all: on phase-matrix models (PTFE's in-plane rows, 1,728 numbers, D 28 and 37; the 84-point set, D 24)
# the exact gradient was 1.7-8.8x faster but its L-BFGS-B stopped short (reached the best maximum in 2/3, 0/3, 0/3
# seeds against finite differences' 3/3, 1/3, 3/3; smoothing the realizability construction's abs and max changed
# nothing: 0-1/3 on the 84-point set): those sets stay below the rule's threshold
_GRADIENT_PAYS = 100_000


def multistart(posterior: Posterior, rng: np.random.Generator, points: int = 8192, polish: int = 8,
               gradient: bool | None = False) -> tuple[float, np.ndarray]:
    """Best of ``polish`` L-BFGS-B runs started at the best of ``points`` Sobol points in the prior cube;
    ``gradient``: exact JAX gradients (``differentiable.cube_objective``) or batched finite differences
    (the default; ``None`` picks gradients where they pay, on large data sets)."""
    if gradient is None:
        gradient = posterior.likelihood.n_obs * (posterior.ndim + 1) > _GRADIENT_PAYS
    from scipy.stats import qmc

    objective, priors = NegativeLogPosterior(posterior), posterior.priors

    def f(u):
        return objective(priors.rescale(np.clip(u, 0.0, 1.0)))

    u = qmc.Sobol(priors.ndim, rng=np.random.default_rng(rng.integers(2**63))).random(points)
    batch = posterior.likelihood.batch_sets
    values = np.concatenate([f(u[i : i + batch]) for i in range(0, points, batch)])
    starts = u[np.argsort(values)[:polish]]
    best_value, best_u = np.inf, starts[0]
    if gradient:
        value_and_gradient = cube_objective(posterior)
    for start in starts:
        value, u = local_search.polish_with_gradient(value_and_gradient, start) if gradient else local_search.polish(f, start)
        if value < best_value:
            best_value, best_u = value, u
    theta = priors.rescale(best_u[None, :])[0]
    return float(posterior.log_prob(theta[None, :])[0]), theta
