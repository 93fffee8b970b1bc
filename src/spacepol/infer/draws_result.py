"""What a posterior's draws become: the one ``Result`` (ArviZ groups, diagnostics, PSIS-LOO) and its run summary
(quantiles, fit, noise against the measured noise, identifiability, residual structure), for every engine."""

from __future__ import annotations

import time

import numpy as np

from ..observables import registry
from ..physics.model_spec import spec_of
from .diagnostics import convergence, fit_statistics, loo, quantile_dict, quantiles
from .engine_result import EngineResult
from .identifiability import identifiability
from .inference_data import median_fit, to_inference_data
from .posterior import Posterior
from .result import Result
from .run_summary import RunSummary


def result_of(posterior: Posterior, draws: EngineResult, rng: np.random.Generator, seed: int, start: float,
              engine: str | None = None) -> Result:
    """The Result of a sampler's draws (any engine): ArviZ groups, R-hat and ESS, PSIS-LOO and the summary."""
    idata = to_inference_data(draws, posterior, rng)
    diagnostics = {**convergence(idata, draws), "engine": engine or draws.method}
    return summarised(posterior, draws, idata, loo(idata), diagnostics, seed, start)


def summarised(posterior: Posterior, result: EngineResult, idata, loo_result: dict, diagnostics: dict, seed: int,
               start: float) -> Result:
    """The Result of a posterior's draws: summary (quantiles, fit, noise ratios, identifiability, residual
    structure) and the ArviZ groups."""
    median = median_fit(posterior, result.flat_samples())  # the fit statistics' and the residual analysis' prediction
    summary = RunSummary(
        model=posterior.likelihood.model.name,
        # the whole model: what contrast rebuilds
        spec=spec_of(posterior.likelihood.model, posterior.likelihood.data.wavelength_um),
        parameters=quantiles(result),
        engine=diagnostics["engine"],  # what drew the posterior (emcee where the Laplace engine was refused)
        diagnostics=diagnostics,
        fit=fit_statistics(posterior, result, loo_result, median),
        seconds=time.perf_counter() - start,
        seed=seed,
        observables=posterior.likelihood.observables,
        observables_not_fitted=dict(posterior.likelihood.left_out),  # {name: the fitted observable holding it}
        # a user's observable and the file it came from ("path.py:Name", "entry point X")
        observable_plugins={o.name: registry.sources[o.name] for o in posterior.likelihood.objects
                        if o.name in registry.sources},
        n_observations=posterior.likelihood.n_obs,
        priors=posterior.priors.describe(),
        fixed={k: float(v) for k, v in posterior.priors.fixed.items()},
        map=result.best,
        sampler={k: v for k, v in result.info.items() if k not in ("tau", "start_search")} | {"tau": result.info.get("tau")},
        pareto_k_bad=loo_result["pareto_k_bad"],
    )
    if "log_evidence" in result.info:  # an engine that estimates the evidence (nested sampling, Laplace-IS)
        summary.log_evidence = {"value": float(result.info["log_evidence"]),
                               "error": float(result.info.get("log_evidence_error", np.nan))}
    if "start_search" in result.info:  # the modes the start-point searches found (infer.modes)
        summary.start_search = result.info["start_search"]
    noise = noise_ratios(posterior, summary.parameters)
    if noise:
        summary.noise = noise
    derived = getattr(posterior.likelihood.model, "derived", None)
    if derived is not None:  # values a dispersion law implies per wavelength (n@0.633 from A and B)
        values = derived(posterior.priors.to_params(result.flat_samples()))
        summary.derived = {name: quantile_dict(np.asarray(v, float).ravel()) for name, v in values.items()}
    ident = identifiability(posterior, result)
    summary.identifiability = {k: ident[k] for k in ("weak", "correlated_pairs", "at_bound", "findings", "width_ratio")}
    from .residuals import analyse

    structure = analyse(posterior, result.flat_samples(), median)
    summary.residual_structure = {"runs": structure.runs, "lag1": structure.lag1, "findings": structure.findings(),
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
