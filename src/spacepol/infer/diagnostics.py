"""Convergence and fit diagnostics (ArviZ for R-hat, ESS and PSIS-LOO)."""

from __future__ import annotations

import warnings

import arviz as az
import numpy as np

from .inference_data import median_fit, model_dop
from .posterior import Posterior
from .psis import logsumexp_rows, psis_log_weights
from .engine_result import EngineResult
from .run_summary import RunSummary


def convergence(idata, result: EngineResult) -> dict:
    """R-hat (rank-normalised) and bulk and tail ESS per parameter from ArviZ, their worst values, and the engine's
    autocorrelation time and acceptance fraction where it reports them."""
    rhat = az.rhat(idata)
    ess_bulk = az.ess(idata, method="bulk")
    ess_tail = az.ess(idata, method="tail")
    names = list(idata.posterior.data_vars)
    return {
        "rhat_max": float(max(rhat[n].item() for n in names)),
        "ess_min": float(min(min(ess_bulk[n].item(), ess_tail[n].item()) for n in names)),
        "ess_bulk_min": float(min(ess_bulk[n].item() for n in names)),
        "ess_tail_min": float(min(ess_tail[n].item() for n in names)),
        "tau_max": float(result.info.get("tau_max", np.nan)),
        "acceptance": float(result.info.get("acceptance", np.nan)),
        "per_parameter": {n: {"rhat": float(rhat[n].item()), "ess_bulk": float(ess_bulk[n].item()),
                              "ess_tail": float(ess_tail[n].item())} for n in names},
    }


def loo(idata) -> dict:
    """PSIS-LOO of the draws in ``idata`` (its log_likelihood group, variable "y"): ``loo_fields``' record, as
    ``arviz.loo`` computes it (the relative efficiency from the posterior group's mean ESS where there are several
    chains; then ``psis.psis_log_weights``, ArviZ's smoothing vectorised over the observations, where ArviZ's own
    loop over them is slow on large data sets). Where PSIS fails for an observation, its in-sample log
    predictive density stands in and its Pareto k is set to inf."""
    ll = idata.log_likelihood["y"].transpose("obs_id", "chain", "draw").values
    ll = ll.reshape(ll.shape[0], -1)  # (M, S): ArviZ's stacking of (chain, draw)
    reff = relative_efficiency(idata.posterior, ll.shape[1]) if len(idata.posterior.chain) > 1 else 1.0
    pointwise, k, p_loo = psis_loo(ll, reff)
    return loo_fields(pointwise, k, p_loo, idata.log_likelihood["obs_id"].values)


def relative_efficiency(posterior, n_samples: int) -> float:
    """ArviZ's relative efficiency of ``n_samples`` draws taken from a posterior's (an xarray Dataset, chains x
    draws): the mean ESS of its parameters over ``n_samples``, as ``arviz.loo`` computes it."""
    ess_p = az.ess(posterior, method="mean")
    return float(np.hstack([ess_p[v].values.flatten() for v in ess_p.data_vars]).mean() / n_samples)


def psis_loo(ll: np.ndarray, reff: float = 1.0) -> tuple[np.ndarray, np.ndarray, float]:
    """(pointwise ELPD-LOO, Pareto k, p_loo) of log likelihoods ``ll`` (observations, draws), as ``loo`` computes
    them."""
    n_samples = ll.shape[1]
    with warnings.catch_warnings(), np.errstate(invalid="ignore", over="ignore"):
        warnings.simplefilter("ignore")
        log_weights, k = psis_log_weights(-ll, reff)
        pointwise = logsumexp_rows(log_weights + ll)
        lppd = float(np.sum(logsumexp_rows(ll) - np.log(n_samples)))
    p_loo = lppd - float(pointwise.sum())
    failed = ~np.isfinite(pointwise)
    if failed.any():
        # PSIS breaks down (NaN) where one observation's log-likelihood spans hundreds of units across the
        # draws: take its in-sample log predictive density instead (an overestimate of its ELPD) and flag
        # it as a bad Pareto k, so the report says LOO is unreliable there
        pointwise[failed] = logsumexp_rows(ll[failed]) - np.log(n_samples)
        k[failed] = np.inf
    return pointwise, k, p_loo


PARETO_K_LIMIT = 0.7  # above it an importance-sampling estimate is unreliable (Vehtari et al., JMLR 25(72), 2024)


def loo_fields(pointwise: np.ndarray, pareto_k: np.ndarray, p_loo: float, labels) -> dict:
    """PSIS-LOO's record from its pointwise values: ELPD-LOO, its standard error, p_loo, the Pareto k per
    observation and the labels of those above ``PARETO_K_LIMIT``."""
    labels, n = list(labels), pointwise.size
    return {"elpd_loo": float(pointwise.sum()), "elpd_loo_se": float(np.sqrt(n * np.var(pointwise))),
            "p_loo": float(p_loo), "pareto_k": pareto_k,
            "pareto_k_bad": [labels[i] for i in np.flatnonzero(pareto_k > PARETO_K_LIMIT)], "pointwise": pointwise}


def fit_statistics(posterior: Posterior, result: EngineResult, loo_result: dict, median: tuple | None = None) -> dict:
    """RMSE of DOP (also when DOP is not fitted but measured: a Mueller fit predicts it) and reduced chi^2
    at the posterior-median prediction; ``median``: ``median_fit`` of the result's draws where already computed."""
    lik = posterior.likelihood
    mu, scale = median or median_fit(posterior, result.flat_samples())
    chi2 = sum(float(np.sum(lik.standardise(o, mu[o], scale[o]) ** 2)) for o in lik.observables)
    rmse = None
    if lik.data.dop is not None:
        predicted = mu["dop"] if "dop" in lik.observables else model_dop(posterior, result.flat_samples())
        rmse = float(np.sqrt(np.mean((lik.data.dop - predicted) ** 2)))
    dof = max(lik.n_obs - posterior.ndim, 1)
    return {"rmse_dop": rmse, "chi2_red": chi2 / dof, "elpd_loo": loo_result["elpd_loo"],
            "elpd_loo_se": loo_result["elpd_loo_se"]}


def quantiles(result: EngineResult) -> dict:
    """``quantile_dict`` of every free parameter's draws, by name."""
    flat = result.flat_samples()
    return {name: quantile_dict(flat[:, j]) for j, name in enumerate(result.names)}


def quantile_dict(values) -> dict:
    """Median and the 5, 16, 84 and 95 % quantiles of ``values`` (summary.json's fields)."""
    q = np.percentile(values, [5, 16, 50, 84, 95])
    return {"median": float(q[2]), "q05": float(q[0]), "q16": float(q[1]), "q84": float(q[3]), "q95": float(q[4])}


def _noise_names() -> tuple[str, ...]:
    from ..observables import every

    names = [o.noise_parameter(ch).name for o in every() for ch in o.channels]
    return tuple(dict.fromkeys(names))


def inferred_noise_levels(summary: RunSummary) -> dict[str, float]:
    """{nuisance: posterior median} of the noise levels a run inferred (empty when the file gave errors)."""
    return {n: summary.parameters[n]["median"] for n in _noise_names() if n in summary.parameters}


def fit_words(chi2_red: float, noise: dict[str, float]) -> str:
    """The error measure that means something for a fit: reduced chi^2 with known noise; with
    inferred noise (chi^2 ~ 1 by construction) the inferred noise levels."""
    if noise:
        return "inferred noise " + ", ".join(f"{k} {v:.3g}" for k, v in noise.items())
    return f"reduced chi^2 {chi2_red:.2f}"


def describe_fit(summary: RunSummary) -> str:
    """``fit_words`` of a run's summary, and where the data measure their own noise, the misfit per group
    (inferred / measured noise)."""
    return fit_words(summary.fit["chi2_red"], inferred_noise_levels(summary)) + misfit_words(summary.noise)


def misfit_words(noise: dict | None) -> str:
    """"; misfit (inferred / measured noise) GROUP RATIO, ..." for summary.json's ``noise``, "" without it."""
    if not noise:
        return ""
    return "; misfit (inferred / measured noise) " + ", ".join(f"{k} {v['ratio']:.2f}" for k, v in noise.items())
