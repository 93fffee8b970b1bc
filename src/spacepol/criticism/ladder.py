"""The ladder: fit M, then M changed once, twice, ... (added, replaced or removed effects); show the error
fall rung by rung."""

from __future__ import annotations

import sys

import numpy as np

from ..infer.diagnostics import inferred_noise_levels
from ..infer.inversion import invert
from ..infer.optimum import find_optimum
from ..infer.posterior import Posterior
from ..physics.model import Model
from .changes import parse, start_points
from .records import Rung


def climb(data, model: Model, additions: list[str], seed: int = 0, observables=None, max_steps: int = 8000,
          progress: bool = True, fitted: dict | None = None) -> list[Rung]:
    """One rung per change: ``additions`` are effect names or change labels ("replace shadowing by smith",
    "remove body"), applied in order.  ``fitted``: {model name: Result} already at hand on these data
    (e.g. from diagnose); reused."""
    rungs, current, fitted = [], model, fitted or {}
    for step in [None] + list(additions):
        change = None
        if step is not None:
            change = parse(current, step)
            current = change.model
        inv = fitted.get(current.name)
        if inv is None:
            if progress:
                print(f"  [rung {len(rungs)}/{len(additions)}] fitting {current.name} with emcee ...", file=sys.stderr, flush=True)
            post = Posterior.build(data, current, observables=observables)
            centre = None
            if rungs:  # start from the previous rung's optimum, the change's new parameters at neutral values
                seeds = start_points(rungs[-1].inversion.summary.map, change, post)
                centre = find_optimum(post, np.random.default_rng(seed), evaluations=4000, seeds=seeds)[1]
            inv = invert(post, seed=seed, max_steps=max_steps, progress=False, centre=centre)
        fit, noise = inv.summary.fit, inferred_noise_levels(inv.summary)
        evidence = rung_evidence(inv, seed)
        rungs.append(Rung({"model": current.name, "change": None if change is None else change.label,
                      "rmse_dop": fit["rmse_dop"], "chi2_red": fit["chi2_red"],
                      "elpd_loo": fit["elpd_loo"], "elpd_loo_se": fit["elpd_loo_se"],
                      "log_evidence": None if evidence is None else evidence[0],
                      "log_evidence_error": None if evidence is None else evidence[1],
                      "inferred_noise": noise, "noise_known": not noise, "noise": inv.summary.noise,
                      "rhat_max": inv.summary.diagnostics["rhat_max"],
                      "pareto_k": inv.summary.diagnostics.get("pareto_k"), "parameters": inv.summary.parameters,
                      "at_bound": inv.summary.at_bound,
                      "residual_structure": inv.summary.residual_findings}, inv))
    return rungs


def rung_evidence(result, seed: int) -> tuple[float, float] | None:
    """A rung's (ln Z, error): the Result's own where its engine gave one, else Laplace-IS at its best point where
    the importance weights are trusted (None where they are not: a ridge or a parameter at a bound; run the rung
    with ``--engine nested`` for it)."""
    if result.log_evidence is not None or result.posterior is None:
        return result.log_evidence
    from ..infer.laplace import laplace_importance

    names = result.posterior.names
    centre = np.array([result.draws.best[n] for n in names], float)
    sample = laplace_importance(result.posterior, centre, np.random.default_rng(seed))
    return sample.log_evidence if sample is not None and sample.reliable else None
