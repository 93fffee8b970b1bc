"""The ``laplace`` engine: a Laplace approximation at the posterior's optimum corrected by importance sampling
(``infer.laplace``), with emcee where its checks refuse it; the default posterior of ``diagnose``'s candidate fits."""

from __future__ import annotations

import sys
import time

import numpy as np

from ..draws_result import summarised
from ..engine_result import EngineResult
from ..inference_data import batched, to_inference_data
from ..laplace import WIDTH_EFFECTIVE_DRAWS, importance_loo, laplace_importance, scale_ridge
from ..posterior import Posterior
from ..result import Result
from ..spread_check import spread_check
from .base import SAMPLER, Engine
from .emcee_engine import check_resumable, invert


def invert_laplace(posterior: Posterior, centre, seed: int = 0, draws: int = 2000) -> Result | None:
    """The posterior from a Laplace approximation at the mode nearest ``centre``, corrected by Pareto-smoothed
    importance sampling (``laplace``): ``draws`` equally weighted draws resampled from as many weighted ones, and
    PSIS-LOO that accounts for the approximation. None where the approximation cannot be trusted (Pareto k > 0.7,
    fewer than 400 effective draws, weights collapsed onto the mode, emcee walkers started inside the draws spreading
    beyond them (``spread_check``; not run where the weights are bounded), no negative definite Hessian): the caller samples
    with emcee (``invert``); ``laplace_fit`` says why. ``summary.diagnostics`` holds the weights' Pareto k and
    effective draws; R-hat and tau do not apply."""
    return laplace_fit(posterior, centre, seed, draws)[0]


NO_LAPLACE = "no negative definite Hessian at the mode (or the log posterior is not finite there)"


def laplace_fit(posterior: Posterior, centre, seed: int = 0, draws: int = 2000) -> tuple[Result | None, str]:
    """(``invert_laplace``'s Result, "") where the approximation is trusted, else (None, why not in words: the failed
    checks with their figures)."""
    start = time.perf_counter()
    ridge = scale_ridge(posterior)
    if ridge:
        return None, ridge
    rng = np.random.default_rng(seed)
    sample = laplace_importance(posterior, centre, rng, draws=draws, width_draws=WIDTH_EFFECTIVE_DRAWS)
    if sample is None:
        return None, NO_LAPLACE
    if not sample.reliable:
        return None, sample.refusal
    # its own stream, so the draws kept below are those of a run without the check
    spread = spread_check(posterior, sample, rng.spawn(1)[0])
    if spread.refusal:
        return None, spread.refusal
    kept = sample.resample(rng, draws)  # the weighted draws may be more than ``draws`` (laplace.MAX_DRAWS)
    names = list(posterior.names)
    centre = np.asarray(centre, float)
    centre_value = float(posterior.log_prob(centre[None, :])[0])
    best = centre if centre_value >= sample.log_prob.max() else sample.theta[int(np.argmax(sample.log_prob))]
    log_z, log_z_error = sample.log_evidence  # importance sampling's evidence, trusted where the weights are
    info = {"engine": "laplace-is", "draws": len(sample.theta), "pareto_k": sample.pareto_k, "effective_draws": sample.effective_draws,
            "proposal": sample.proposal, "log_evidence": log_z, "log_evidence_error": log_z_error,
            "spread_check": spread.to_json()}
    result = EngineResult(method="laplace-is", model=posterior.likelihood.model.name, names=names,
                    best=dict(zip(names, map(float, best))), objective=-float(max(centre_value, sample.log_prob.max())),
                    objective_name="negative_log_posterior", n_evaluations=posterior.n_evaluations,
                    seconds=time.perf_counter() - start, seed=seed, samples=sample.theta[kept][:, None, :],
                    log_prob=sample.log_prob[kept][:, None], info=info)
    idata = to_inference_data(result, posterior, rng, draws)
    lik = posterior.likelihood
    # PSIS-LOO from the first ``draws`` draws (independent draws of one proposal, as all of them are): more draws drawn
    # for the walkers' check would multiply the pointwise evaluation on a large data set
    log_likelihood = batched(posterior.log_prob_pointwise, sample.theta[:draws], lik.batch_sets)
    loo_result = importance_loo(log_likelihood, sample.raw_log_weights[:draws], lik.labels)
    diagnostics = {"engine": "laplace-is", "rhat_max": None, "ess_min": sample.effective_draws, "tau_max": None,
                   "acceptance": None, "pareto_k": sample.pareto_k, "sd_growth_max": spread.widest[1]}
    return summarised(posterior, result, idata, loo_result, diagnostics, seed, start), ""


class Laplace(Engine):
    """A Laplace approximation at the posterior's optimum, corrected by importance sampling; where its checks refuse
    it (Pareto k, effective draws, width, the walkers' spread), emcee samples instead and the Result says so
    (``summary.diagnostics["engine"]`` names what ran, ``summary.laplace_refused`` why)."""

    name, kind, resumable = "laplace", SAMPLER, True  # its emcee fallback keeps its chain, so an interrupted run continues
    description = "Laplace approximation at the optimum corrected by importance sampling; emcee where it cannot be trusted"

    def approximate(self, posterior, centre, seed: int = 0, draws: int = 2000):
        """(Result, "") where the approximation at ``centre`` (an optimum) is trusted, else (None, why not in words):
        ``inversion.laplace_fit``, no fallback."""
        return laplace_fit(posterior, centre, seed=seed, draws=draws)

    def run(self, posterior, rng, draws: int = 2000, progress: bool = False):
        """Equally weighted draws resampled from the importance-weighted ones (emcee's where refused)."""
        return self.result(posterior, int(rng.integers(2**31)), draws=draws, progress=progress).draws

    def result(self, posterior, seed: int = 0, progress: bool = False, chain=None, draws: int = 2000, **options):
        """``inversion.laplace_fit`` at the optimum the start-point search finds; where its checks refuse the
        approximation, one line saying which (the refusal's figures) and ``inversion.invert`` from that optimum."""
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
        result.summary.laplace_refused = refusal
        return result

    def check_chain(self, chain, posterior, seed: int, **_) -> None:
        """A chain its emcee fallback left in ``chain`` must belong to this run (before any work)."""
        check_resumable(chain, posterior, None, seed)
