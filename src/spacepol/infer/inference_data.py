"""Posterior samples -> ArviZ InferenceData (posterior, posterior_predictive, log_likelihood,
sample_stats, observed_data), so ArviZ computes R-hat, ESS and PSIS-LOO."""

from __future__ import annotations

import warnings

import arviz as az
import numpy as np

from .posterior import Posterior
from .engine_result import EngineResult


# Pointwise groups (log-likelihood, replicates) hold draws x observations numbers; above this many the
# draws are thinned for them (never below _MIN_POINTWISE_DRAWS): PSIS-LOO needs hundreds of draws, not 10^4.
_POINTWISE_VALUES = 40_000_000
_MIN_POINTWISE_DRAWS = 800
# a posterior median prediction from at most this many evenly thinned draws: its Monte-Carlo error is then below
# 4 % of the posterior SD, and more draws only cost time
_MEDIAN_DRAWS = 1000


def batched(fn, flat, batch: int):
    """fn over blocks of ``batch`` rows (the compiled programs pad a remainder to a size they were compiled for)."""
    return np.concatenate([fn(flat[i : i + batch]) for i in range(0, len(flat), batch)], axis=0)


def predictive_means(posterior: Posterior, flat_theta) -> dict[str, np.ndarray]:
    """Noise-free model predictions for each parameter set: {observable: (S, N)}."""
    lik = posterior.likelihood

    def one(block):
        pred = lik.predict(posterior.model_params(block))
        return np.stack([pred[o] for o in lik.observables], axis=0).transpose(1, 0, 2)

    stacked = batched(one, flat_theta, lik.batch_sets)  # (S, n_observables, N)
    return {o: stacked[:, i, :] for i, o in enumerate(lik.observables)}


def model_dop(posterior: Posterior, flat_theta, draws: int = 200) -> np.ndarray:
    """Posterior-median model DOP at the data's geometries, also where DOP is not fitted (a Mueller fit
    predicts it from its first column): (N,). Up to ``draws`` evenly thinned samples. Evaluated by the program
    that ``predictive_means`` compiled already (the same outputs and batch size): a DOP-only program of its own
    would cost one more compilation per fit."""
    lik = posterior.likelihood
    params = posterior.model_params(flat_theta[:: max(1, len(flat_theta) // draws)])
    prediction = lik.model.evaluate(params, lik.geometry, mueller=lik.needs_mueller, check=False)
    return np.median(np.atleast_2d(prediction.dop), axis=0)


def noise_scales(posterior: Posterior, flat_theta) -> dict[str, np.ndarray]:
    """The noise level per channel and draw: (S, N) arrays (file errors or inferred)."""
    lik = posterior.likelihood
    params = posterior.priors.to_params(flat_theta)
    shape = (len(flat_theta), len(lik.data))
    return {ch: np.broadcast_to(lik.scale(ch, params), shape) for ch in lik.observables}


def median_fit(posterior: Posterior, samples):
    """Posterior-median prediction and noise level per channel: ({ch: (N,)}, {ch: (N,)}), from at most
    ``_MEDIAN_DRAWS`` evenly thinned samples."""
    samples = samples[:: max(1, int(np.ceil(len(samples) / _MEDIAN_DRAWS)))]
    means, scales = predictive_means(posterior, samples), noise_scales(posterior, samples)
    return ({o: np.median(m, axis=0) for o, m in means.items()}, {o: np.median(v, axis=0) for o, v in scales.items()})


def standardised_residuals(posterior: Posterior, samples) -> dict[str, np.ndarray]:
    """(data - posterior-median prediction) / noise per fitted channel, the noise at its posterior median."""
    mu, scale = median_fit(posterior, samples)
    lik = posterior.likelihood
    return {ch: lik.standardise(ch, mu[ch], scale[ch]) for ch in lik.observables}


def replicate(posterior: Posterior, means, scales, rng: np.random.Generator):
    """Replicated data y_rep = prediction + noise drawn like the measurement's."""
    lik = posterior.likelihood
    return {ch: lik.replicate(ch, mu, scales[ch], rng) for ch, mu in means.items()}


def to_inference_data(result: EngineResult, posterior: Posterior, rng: np.random.Generator,
                      max_pointwise_draws: int | None = None) -> az.InferenceData:
    """The run as ArviZ groups; the pointwise groups (log_likelihood, posterior_predictive) from every k-th draw
    (``pointwise_thinning``), at most ``max_pointwise_draws`` draws in all when given."""
    samples = result.samples  # (draws, chains, D)
    draws, chains, ndim = samples.shape
    lik = posterior.likelihood
    n = len(lik.data)
    flat = samples.transpose(1, 0, 2).reshape(-1, ndim)  # chain-major
    step = pointwise_thinning(draws, chains, lik.n_obs)
    if max_pointwise_draws:
        step = max(step, int(np.ceil(draws * chains / max_pointwise_draws)))
    kept = len(range(0, draws, step))
    flat_kept = samples[::step].transpose(1, 0, 2).reshape(-1, ndim)
    loglik = batched(posterior.log_prob_pointwise, flat_kept, lik.batch_sets)  # (S', M)
    means = predictive_means(posterior, flat_kept)
    reps = replicate(posterior, means, noise_scales(posterior, flat_kept), rng)

    def shaped(a, d=draws):
        return a.reshape(chains, d, *a.shape[1:])

    geometry = {"theta_i": ("geometry", lik.data.theta_i), "theta_r": ("geometry", lik.data.theta_r),
                "dphi": ("geometry", lik.data.dphi)}
    with warnings.catch_warnings():  # emcee's walkers are ArviZ's chains: few thinned draws per walker are normal
        warnings.filterwarnings("ignore", message="More chains")
        idata = az.from_dict(
            posterior={name: shaped(flat[:, j]) for j, name in enumerate(posterior.names)},
            posterior_predictive={o: shaped(r, kept) for o, r in reps.items()},
            log_likelihood={"y": shaped(loglik, kept)},
            sample_stats={"lp": shaped(result.log_prob.T.reshape(-1))},
            observed_data=lik.observed(),
            constant_data={k: v[1] for k, v in geometry.items()},
            coords={"geometry": np.arange(n), "obs_id": lik.labels},
            dims={**{o: ["geometry"] for o in lik.observables}, "y": ["obs_id"],
                  **{k: ["geometry"] for k in geometry}},
        )
    idata.posterior.attrs.update({
        "model": result.model, "method": result.method, "seed": result.seed,
        "walkers": result.info.get("walkers", chains), "burn_in": result.info.get("burn_in", 0),
        "thin": result.info.get("thin", 1), "steps": result.info.get("steps", draws),
    })
    idata.posterior_predictive.attrs["mean_prediction"] = "y_rep = model + noise drawn as in the likelihood"
    for group in (idata.posterior_predictive, idata.log_likelihood):
        group.attrs["every_kth_posterior_draw"] = step
    return idata


def pointwise_thinning(draws: int, chains: int, n_obs: int) -> int:
    """Every k-th draw for the pointwise groups: all of them unless draws x chains x observations exceeds
    _POINTWISE_VALUES, and never fewer than _MIN_POINTWISE_DRAWS draws in all."""
    total = draws * chains
    step = max(1, int(np.ceil(total * n_obs / _POINTWISE_VALUES)))
    return max(1, min(step, total // _MIN_POINTWISE_DRAWS))


def for_storage(idata: az.InferenceData, max_values: int = 3_000_000) -> az.InferenceData:
    """A copy small enough to keep: the posterior, sample_stats and data groups whole; the
    pointwise groups (log_likelihood, posterior_predictive), which grow with the number of
    observations, thinned to at most ``max_values`` numbers each (every k-th draw of every chain)
    and stored as float32 (7 significant digits, far below Monte-Carlo error).  The summary's
    R-hat, ESS and ELPD-LOO were computed on the full groups before thinning."""
    out = idata.copy()
    for group in ("log_likelihood", "posterior_predictive"):
        if group not in out.groups():
            continue
        ds = out[group]
        per_draw = sum(int(np.prod([n for d, n in v.sizes.items() if d not in ("chain", "draw")])) for v in ds.data_vars.values())
        total = ds.sizes["chain"] * ds.sizes["draw"] * max(per_draw, 1)
        step = max(1, int(np.ceil(total / max_values)))
        thinned = ds.isel(draw=slice(None, None, step)).astype(np.float32)
        thinned.attrs.update(ds.attrs)
        thinned.attrs["stored_every_kth_draw"] = step
        thinned.attrs["note"] = "thinned and float32 for storage; summary.json holds the full-chain statistics"
        setattr(out, group, thinned)
    return out
