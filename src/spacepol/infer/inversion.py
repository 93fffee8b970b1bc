"""A full Bayesian inversion: posterior -> emcee (or a Laplace approximation corrected by importance sampling) ->
InferenceData -> diagnostics -> summary."""

from __future__ import annotations

import hashlib
import time
from pathlib import Path

import h5py
import numpy as np

from ..errors import SpacepolError
from ..observables import registry
from ..physics.model_spec import spec_of
from .chain_file import chain_iterations, compact
from .diagnostics import convergence, fit_statistics, loo, quantile_dict, quantiles
from .elpd_settled import settled
from .engines.emcee_sampler import ball, default_walkers, sample_emcee
from .identifiability import identifiability
from .inference_data import batched, to_inference_data
from .laplace import importance_loo, laplace_importance, scale_ridge
from .posterior import Posterior
from .engine_result import EngineResult
from .result import Result
from .sampling_space import SamplingSpace
from .spread_check import spread_check


def fingerprint(posterior: Posterior, walkers: int, seed: int, space: str = SamplingSpace.family) -> str:
    """A short hash of what decides a chain (model, priors, observables, data, walkers, seed, sampling space): a stored
    chain resumes only under the same fingerprint."""
    lik = posterior.likelihood
    h = hashlib.sha256()
    h.update(lik.model.name.encode())
    h.update(repr(sorted(posterior.priors.describe().items())).encode())
    h.update(repr(lik.observables).encode())
    h.update(np.ascontiguousarray(np.column_stack([lik.data.theta_i, lik.data.theta_r, lik.data.dphi])).tobytes())
    observed = lik.observed()
    for o in lik.observables:
        h.update(np.ascontiguousarray(observed[o]).tobytes())
    h.update(f"{walkers}:{seed}:{space}".encode())  # the chain file holds the sampler's coordinates
    return h.hexdigest()[:16]


def _check_backend(path: Path, print_: str) -> None:
    if not path.exists():
        return
    chain_iterations(path)  # a damaged file: one line with the remedy
    with h5py.File(path, "r") as f:
        stored = f.attrs.get("spacepol_fingerprint")
    if stored is not None and stored != print_:
        raise SpacepolError(f"{path}: holds the chain of a different run (model, data, priors, walkers or seed); "
                            f"add --restart to start afresh (the old chain is kept as {path.name}.old) or use another --out")


def _stamp_backend(path: Path, print_: str) -> None:
    with h5py.File(path, "a") as f:
        f.attrs["spacepol_fingerprint"] = print_


def check_resumable(path, posterior: Posterior, walkers: int | None, seed: int) -> None:
    """Before any work: a chain already in ``path`` must be readable and belong to this run."""
    _check_backend(Path(path), fingerprint(posterior, check_walkers(walkers, posterior.ndim), seed))


def check_walkers(walkers: int | None, ndim: int) -> int:
    """The number of walkers to use (the default when None); an impossible count is an error."""
    walkers = default_walkers(ndim) if walkers is None else walkers
    if walkers < 2 * ndim or walkers % 2:
        raise SpacepolError(f"--walkers {walkers}: need an even number >= 2 x {ndim} parameters = {2 * ndim}")
    return walkers


def invert(posterior: Posterior, seed: int = 0, walkers: int | None = None, max_steps: int = 20000,
           backend_path=None, progress: bool = True, check_every: int = 500, centre=None, space=None,
           tau_multiple: float = 50.0, max_pointwise_draws: int | None = None, elpd_tolerance: float | None = None) -> Result:
    """emcee posterior and its summary. ``centre``: a parameter vector (e.g. an optimum already found)
    around which the walkers start; by default a global optimisation finds one. ``space``: where the walkers
    move (``sampling_space``; default the logit of each prior's CDF). ``tau_multiple``: the chain is long
    enough at this many autocorrelation times (with R-hat <= 1.01 and ESS >= 400 besides).
    ``max_pointwise_draws``: PSIS-LOO and the posterior predictive from at most this many draws. ``elpd_tolerance``:
    for a caller that needs the ELPD-LOO alone (diagnose), the chain may stop before convergence where the ELPD-LOO
    of its two halves agree within this many log units (``elpd_settled``; ``summary["sampler"]["stopped_early"]``)."""
    start = time.perf_counter()
    rng = np.random.default_rng(seed)
    walkers = check_walkers(walkers, posterior.ndim)
    if backend_path is not None:
        backend_path = Path(backend_path)
        print_ = fingerprint(posterior, walkers, seed, (space or SamplingSpace).family)
        _check_backend(backend_path, print_)
        _stamp_backend(backend_path, print_)  # before sampling, so an interrupted chain is recognised
    result = sample_emcee(posterior, rng, walkers=walkers, max_steps=max_steps, backend_path=backend_path,
                          progress=progress, model_name=posterior.likelihood.model.name, seed=seed,
                          check_every=check_every, space=space, tau_multiple=tau_multiple,
                          initial=None if centre is None else ball(posterior, np.asarray(centre, float), walkers, rng),
                          enough=None if elpd_tolerance is None else settled(posterior, elpd_tolerance))
    if backend_path is not None:
        compact(backend_path)
    idata = to_inference_data(result, posterior, rng, max_pointwise_draws)
    loo_result = loo(idata)
    return _inversion(posterior, result, idata, loo_result, {**convergence(idata, result), "engine": "emcee"}, seed, start)


def invert_laplace(posterior: Posterior, centre, seed: int = 0, draws: int = 2000) -> Result | None:
    """The posterior from a Laplace approximation at the mode nearest ``centre``, corrected by Pareto-smoothed
    importance sampling (``laplace``): ``draws`` equally weighted draws resampled from as many weighted ones, and
    PSIS-LOO that accounts for the approximation. None where the approximation cannot be trusted (Pareto k > 0.7,
    fewer than 400 effective draws, weights collapsed onto the mode, emcee walkers started inside the draws spreading
    beyond them (``spread_check``), no negative definite Hessian): the caller samples
    with emcee (``invert``); ``laplace_fit`` says why. ``summary["diagnostics"]`` holds the weights' Pareto k and
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
    sample = laplace_importance(posterior, centre, rng, draws=draws)
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
    log_likelihood = batched(posterior.log_prob_pointwise, sample.theta, lik.batch_sets)
    loo_result = importance_loo(log_likelihood, sample.raw_log_weights, lik.labels)
    diagnostics = {"engine": "laplace-is", "rhat_max": None, "ess_min": sample.effective_draws, "tau_max": None,
                   "acceptance": None, "pareto_k": sample.pareto_k, "sd_growth_max": spread.widest[1]}
    return _inversion(posterior, result, idata, loo_result, diagnostics, seed, start), ""


def result_of(posterior: Posterior, draws: EngineResult, rng: np.random.Generator, seed: int, start: float,
              engine: str | None = None) -> Result:
    """The Result of a sampler's draws (any engine): ArviZ groups, R-hat and ESS, PSIS-LOO and the summary."""
    idata = to_inference_data(draws, posterior, rng)
    diagnostics = {**convergence(idata, draws), "engine": engine or draws.method}
    return _inversion(posterior, draws, idata, loo(idata), diagnostics, seed, start)


def _inversion(posterior: Posterior, result: EngineResult, idata, loo_result: dict, diagnostics: dict, seed: int,
               start: float) -> Result:
    """The Result of a posterior's draws: summary (quantiles, fit, noise ratios, identifiability, residual
    structure) and the ArviZ groups."""
    summary = {
        "model": posterior.likelihood.model.name,
        # the whole model: what contrast rebuilds
        "spec": spec_of(posterior.likelihood.model, posterior.likelihood.data.wavelength_um),
        "parameters": quantiles(result),
        "engine": diagnostics["engine"],  # what drew the posterior (emcee where the Laplace engine was refused)
        "diagnostics": diagnostics,
        "fit": fit_statistics(posterior, result, loo_result),
        "seconds": time.perf_counter() - start,
        "seed": seed,
        "observables": posterior.likelihood.observables,
        "observables_not_fitted": dict(posterior.likelihood.left_out),  # {name: the fitted observable holding it}
        # a user's observable and the file it came from ("path.py:Name", "entry point X")
        "observable_plugins": {o.name: registry.sources[o.name] for o in posterior.likelihood.objects
                               if o.name in registry.sources},
        "n_observations": posterior.likelihood.n_obs,
        "priors": posterior.priors.describe(),
        "fixed": {k: float(v) for k, v in posterior.priors.fixed.items()},
        "map": result.best,
        "sampler": {k: v for k, v in result.info.items() if k not in ("tau", "start_search")} | {"tau": result.info.get("tau")},
        "pareto_k_bad": loo_result["pareto_k_bad"],
    }
    if "log_evidence" in result.info:  # an engine that estimates the evidence (nested sampling, Laplace-IS)
        summary["log_evidence"] = {"value": float(result.info["log_evidence"]),
                                   "error": float(result.info.get("log_evidence_error", np.nan))}
    if "start_search" in result.info:  # the modes the start-point searches found (infer.modes)
        summary["start_search"] = result.info["start_search"]
    noise = noise_ratios(posterior, summary["parameters"])
    if noise:
        summary["noise"] = noise
    derived = getattr(posterior.likelihood.model, "derived", None)
    if derived is not None:  # values a dispersion law implies per wavelength (n@0.633 from A and B)
        values = derived(posterior.priors.to_params(result.flat_samples()))
        summary["derived"] = {name: quantile_dict(np.asarray(v, float).ravel()) for name, v in values.items()}
    ident = identifiability(posterior, result)
    summary["identifiability"] = {k: ident[k] for k in ("weak", "correlated_pairs", "at_bound", "findings", "width_ratio")}
    from .residuals import analyse

    structure = analyse(posterior, result.flat_samples())
    summary["residual_structure"] = {"runs": structure.runs, "lag1": structure.lag1, "findings": structure.findings(),
                                     "structured": structure.structured()}
    return Result(posterior, result, idata, summary, loo_result, ident)


EXPLAINED_NOISE_RATIO = 1.5  # a model explains the data when no inferred noise level exceeds the measured one by more


def noise_ratios(posterior: Posterior, parameters: dict) -> dict:
    """summary.json's ``noise``: {noise parameter: {"inferred" (posterior median), "measured", "ratio", ...}} for
    the levels the data measure themselves. The ratio is the misfit the model hides in its inferred noise."""
    out = {}
    for name, measured in posterior.measured_noise.items():
        if name in parameters:
            inferred = float(parameters[name]["median"])
            out[name] = {"inferred": inferred, "measured": measured.value, "ratio": inferred / measured.value,
                         **{k: v for k, v in measured.to_json().items() if k != "measured"}}
    return out


def noise_findings(noise: dict) -> list[str]:
    """One sentence per noise group: misfit = inferred / measured, and whether the model explains the data."""
    out = []
    for name, v in noise.items():
        verdict = ("within the measurement's noise" if v["ratio"] <= EXPLAINED_NOISE_RATIO
                   else "NOT explained: the model hides structure in this noise")
        out.append(f"{name}: misfit = inferred {v['inferred']:.3g} / measured {v['measured']:.3g} "
                   f"(+- {v['standard_error']:.2g}, {v['n_differences']} {v['source']} differences) = {v['ratio']:.2f}: {verdict}")
    return out


def explains(noise: dict) -> bool | None:
    """True when every inferred noise level is within EXPLAINED_NOISE_RATIO of the measured one; None without
    measured noise."""
    return None if not noise else all(v["ratio"] <= EXPLAINED_NOISE_RATIO for v in noise.values())
