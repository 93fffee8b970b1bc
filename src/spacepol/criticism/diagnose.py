"""What is missing or wrong in a model: screen every change (add, replace, remove), confirm the leaders.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import re
import sys
import time

import numpy as np

from ..errors import SpacepolError
from ..infer import elpd_settled
from ..infer.diagnostics import describe_fit, inferred_noise_levels
from ..infer.identifiability import bound_finding
from ..infer.inference_data import median_fit
from ..infer.draws_result import explains
from ..infer.optimum import find_optimum
from ..infer.posterior import Posterior
from ..physics.model import Model
from ..physics.registry import registry
from .candidate_fits import CandidateFits, fit_for_elpd, model_key
from .changes import BLIND_REASON, blind_changes, changes, separating_measurement, separating_observables
from .records import CandidateFit, DiagnosisRecord
from ..infer.run_summary import RunSummary


def _first_sentence(text: str) -> str:
    return re.split(r"(?<!et al)(?<!e\.g)(?<!i\.e)\.\s+(?=[A-Z])", text)[0].rstrip(".") + "."


def check_prior_names(data, model: Model, priors: dict, observables=None, candidates=None) -> None:
    """Every overridden prior must belong to the base model or to one of the candidates."""
    known = {p.name for p in Posterior.build(data, model, observables=observables).priors.parameters}
    for change in changes(model, data, candidates):
        known |= {p.name for p in change.model.parameters}
    unknown = sorted(set(priors or {}) - known)
    if unknown:
        raise SpacepolError(f"--prior: no parameter(s) {', '.join(unknown)} in {model.name} or any candidate effect")


def _global_optimum(posterior, rng, budget, seeds=None):
    value, theta = find_optimum(posterior, rng, evaluations=budget, seeds=seeds)
    return value, dict(zip(posterior.priors.names, theta))


def _vector(values: dict, posterior) -> np.ndarray:
    return np.array([values[n] for n in posterior.priors.names], float)


def diagnose(data, model: Model, rng: np.random.Generator, seed: int = 0, observables=None, candidates=None,
             top: int = 3, screening_evaluations: int = 4000, max_steps: int = 8000, progress: bool = True,
             priors: dict | None = None, base=None, confirm=(), simplifications: int = 0,
             posterior_method: str = "laplace", searched: dict | None = None, workers: int = 1,
             fits: CandidateFits | None = None, criterion: str = "loo") -> DiagnosisRecord:
    """Rank the effects missing from ``model``; ``priors`` overrides default priors by parameter name;
    ``base``: a Result of ``model`` on these data already at hand (it is not refitted); ``confirm``:
    change labels refitted whatever their screening gain; ``simplifications``: how many changes with fewer free
    parameters to refit besides (for diagnose --rounds, which may take one when nothing is significant);
    ``posterior_method``: how each fit's posterior is drawn (``fit_for_elpd``); ``searched``: the maxima already
    found for models on these data with these priors ({``model_key``: (max log posterior, optimum by name)}), used
    instead of a search and filled by this call (diagnose --rounds passes one from round to round: removing the
    effect a round added gives back the model it started from, and replacing it gives a model screened then);
    ``workers``: how many candidates are searched and refitted at once, in worker processes (the answer does not
    depend on it: ``candidate_fits``); ``fits``: a ``CandidateFits`` already open for these data (diagnose --rounds
    keeps one for all its rounds), else one is opened and closed here; ``criterion``: what ranks the refitted
    changes and calls them significant, ``loo`` (delta ELPD-LOO > 2 SE and > 4) or ``evidence`` (ln Bayes factor
    > 3 and > 2 x its error; ln Z from Laplace-IS where trusted, else nested sampling). Each ranking entry holds
    both differences where both are known."""
    if criterion not in CRITERIA:
        raise SpacepolError(f"--criterion {criterion}: unknown ({', '.join(CRITERIA)})")
    if fits is None:
        with CandidateFits(data, observables, priors, workers) as own:
            return diagnose(data, model, rng, seed=seed, observables=observables, candidates=candidates, top=top,
                            screening_evaluations=screening_evaluations, max_steps=max_steps, progress=progress,
                            priors=priors, base=base, confirm=confirm, simplifications=simplifications,
                            posterior_method=posterior_method, searched=searched, fits=own, criterion=criterion)
    check_prior_names(data, model, priors, observables, candidates)
    clock = {"start": time.perf_counter()}
    searched = {} if searched is None else searched
    base_post = fits.posterior(model)
    if _same_posterior(base, base_post):  # compiled already (diagnose --rounds: the last round's lead)
        base_post = base.posterior
    base_post.ensure_checked()
    if model_key(model) not in searched:
        searched[model_key(model)] = _global_optimum(base_post, rng, screening_evaluations)
    base_best, base_optimum = searched[model_key(model)]
    all_candidates = changes(model, data, candidates)
    # changes the fitted observables cannot see (a DOP estimator's bias on Mueller data) are not screened
    blind = blind_changes(all_candidates, base_post.likelihood.objects)
    all_candidates = [c for c in all_candidates if c not in blind]
    if base is None:
        if progress:
            _say(f"[base] fitting {model.name} ({len(data)} geometries) ...")
        base = fit_for_elpd(base_post, _vector(base_optimum, base_post), seed, max_steps, posterior_method)
    base_loo = base.loo["pointwise"]
    base_fit = median_fit(base.posterior, base.draws.flat_samples())
    clock["base"] = time.perf_counter()

    if progress:
        _say(f"[base] done in {clock['base'] - clock['start']:.0f} s; screening {len(all_candidates)} candidate effects")
        if blind:
            _say(f"[screen] not screened: {', '.join(c.label for c in blind)} ({BLIND_REASON})")
    posteriors = [fits.posterior(change.model) for change in all_candidates]
    unsearched = [i for i, change in enumerate(all_candidates) if model_key(change.model) not in searched]

    def screened_line(i: int, done: int) -> None:
        if progress:
            gain = searched[model_key(all_candidates[i].model)][0] - base_best
            _say(f"[screen {done}/{len(all_candidates)}] {all_candidates[i].label:<32s} max log posterior gain {gain:9.2f} "
                 f"({time.perf_counter() - clock['start']:.0f} s)")

    done = 0
    for i in [i for i in range(len(all_candidates)) if i not in unsearched]:
        done += 1
        screened_line(i, done)
    jobs = [(all_candidates[i].model, posteriors[i], all_candidates[i], base_optimum, screening_evaluations)
            for i in unsearched]
    for j, found in fits.run("screen", jobs, rng):
        searched[model_key(all_candidates[unsearched[j]].model)] = found
        done += 1
        screened_line(unsearched[j], done)
    screened = []
    for change, post in zip(all_candidates, posteriors):
        best, optimum = searched[model_key(change.model)]
        screened.append(CandidateFit(change, post, float(best - base_best), _vector(optimum, post)))
    screened.sort(key=lambda c: -c.screening_gain)

    clock["screening"] = time.perf_counter()
    # a candidate whose screening gain equals the leader's may be its twin: confirm it too
    to_confirm = screened[:top] + [c for c in screened[top:] if top and _close(c.screening_gain, screened[0].screening_gain)]
    # effects declared twins of a confirmed addition are refitted too: a tie can only be seen between two fits; not
    # where the fitted observables separate the two (``Effect.separated_by``: the full Mueller matrix for an analyser
    # and depolarized light), where the twin is refitted only if its own screening earns it
    fitted = set(base_post.likelihood.observable_names)
    twins = {t for c in to_confirm if c.kind == "add" for t in registry.get(c.effect).twins
             if not fitted & set(separating_observables(c.effect, t))}
    to_confirm += [c for c in screened if c not in to_confirm and c.kind == "add" and c.effect in twins]
    to_confirm += [c for c in screened if c not in to_confirm and c.label in confirm]
    # the best simplifications (fewer free parameters) that screening does not rule out: if nothing is
    # significant, diagnose --rounds takes one that predicts as well (Occam)
    simpler = [c for c in screened if c not in to_confirm and c.posterior.ndim < base_post.ndim
               and c.screening_gain > -2 * MIN_DELTA_ELPD]
    to_confirm += simpler[:simplifications]
    # screening searched near the base model; a refit starts from the best of that and a global multistart
    leaders = dict(fits.run("leader", [(c.model, c.posterior) for c in to_confirm], rng))
    for i, c in enumerate(to_confirm):
        value, theta = leaders[i]
        if value > c.screening_gain + base_best:
            c.screening_gain, c.optimum = float(value - base_best), theta
            searched[model_key(c.model)] = value, dict(zip(c.posterior.priors.names, theta))
    # changes refitted only because the caller asked (``confirm``: the slot alternatives diagnose --rounds weighs
    # at its end) and that their optima alone already show to differ significantly are not refitted
    asked = [c for c in to_confirm if c.label in confirm]
    if asked:
        best = np.array([base.draws.best[n] for n in base_post.priors.names], float)
        base_pointwise = base_post.log_prob_pointwise(best[None, :])[0]
    decided = [c for c in asked if _plugin_decides(c, base_pointwise, float(base.loo.get("p_loo", 0.0)))]
    to_confirm = [c for c in to_confirm if c not in decided]
    clock["leaders"] = time.perf_counter()
    if progress and to_confirm:
        _say(f"[confirm] refitting {len(to_confirm)}: {', '.join(c.label for c in to_confirm)} "
             f"({time.perf_counter() - clock['start']:.0f} s)")
    # start at the screening optimum: multimodal candidates (film thickness) keep the mode screening found; the
    # best screened first, so that candidates its refit shows to be clearly worse need no refit of their own
    to_confirm.sort(key=lambda c: -c.screening_gain)
    refitted, dominated = [], []

    def refit(batch: list) -> None:
        jobs = [(c.model, c.posterior, c.optimum, seed, max_steps, posterior_method) for c in batch]
        for i, inv in fits.run("refit", jobs, rng):
            c = batch[i]
            diff = inv.loo["pointwise"] - base_loo
            c.inversion, c.pointwise = inv, inv.loo["pointwise"]
            c.delta_elpd, c.delta_elpd_se = float(diff.sum()), float(np.sqrt(len(diff) * np.var(diff)))
            c.rmse_dop_after, c.signatures = inv.summary.fit["rmse_dop"], signatures(base, inv, base_fit)
            c.significant = significant(c.delta_elpd, c.delta_elpd_se)
            refitted.append(c)
            if progress:
                q = posterior_quality(inv)
                refused = f": {q['laplace_refused']}" if q.get("laplace_refused") else ""
                how = ("Laplace-IS" if q["engine"] == "laplace-is"
                       else f"emcee (the Laplace approximation was not trusted{refused})"
                       + ("" if q["converged"] else f", which {_unconverged(q)}"))
                _say(f"[confirm {len(refitted)}/{len(to_confirm) - len(dominated)}] {c.label}: {how}, "
                     f"{inv.summary.seconds:.0f} s ({time.perf_counter() - clock['start']:.0f} s)")

    def weigh(pending: list) -> list:
        """``pending`` less those the best refit so far shows clearly worse (``_dominated``; not the changes asked for)."""
        lead = _front_runner(refitted) if criterion == "loo" else None
        skip = [c for c in pending if lead is not None and c.label not in confirm and _dominated(c, lead)]
        if progress and skip:
            _say(f"[confirm] not refitted, clearly worse than {lead.label}: {', '.join(c.label for c in skip)}")
        dominated.extend(skip)
        return [c for c in pending if c not in skip]

    # the best screened alone first, then the rest at once (so the refits do not depend on the number of workers);
    # every skip is weighed again against the final front-runner, the one a tie would be judged against
    refit(to_confirm[:1])
    refit(weigh(to_confirm[1:]))
    while dominated:
        again = [c for c in dominated if _front_runner(refitted) is None or not _dominated(c, _front_runner(refitted))]
        if not again:
            break
        dominated[:] = [c for c in dominated if c not in again]
        refit(again)
    for c in dominated:
        c.dominated_by = _front_runner(refitted).label
    to_confirm = [c for c in to_confirm if c not in dominated]
    confirmed = [c for c in to_confirm]
    base_evidence = evidence_of(base, base_post, seed) if criterion == "evidence" else base.log_evidence
    for c in confirmed:
        own = evidence_of(c.inversion, c.posterior, seed) if criterion == "evidence" else c.inversion.log_evidence
        if own is not None and base_evidence is not None:
            c.delta_log_evidence = own[0] - base_evidence[0]
            c.delta_log_evidence_error = float(np.hypot(own[1], base_evidence[1]))
        if criterion == "evidence":
            c.significant = significant_evidence(c.delta_log_evidence, c.delta_log_evidence_error)
    if criterion == "evidence":
        confirmed.sort(key=lambda c: -c.delta_log_evidence)
    else:
        confirmed.sort(key=lambda c: -c.delta_elpd)
    if confirmed and confirmed[0].significant:
        # changes that fit equally well (tied with the best): the one with fewer free parameters leads
        group = [c for c in confirmed if c.significant and (c is confirmed[0] or _tied(confirmed[0], c))]
        simplest = min(group, key=lambda c: (c.posterior.ndim, -c.delta_elpd))
        confirmed.remove(simplest)
        confirmed.insert(0, simplest)
    clock["confirmation"] = time.perf_counter()

    ranking = []
    for i, c in enumerate(confirmed):
        entry = {"effect": c.effect, "change": c.label, "delta_elpd": c.delta_elpd, "delta_elpd_se": c.delta_elpd_se,
                 "rmse_dop_after": c.rmse_dop_after, "significant": c.significant,
                 "delta_log_evidence": c.delta_log_evidence, "delta_log_evidence_error": c.delta_log_evidence_error,
                 "explains_misfit": not _structured(c.inversion.summary), "screening_gain": c.screening_gain,
                 "explanation": _explain(c, base)}
        if c.delta_log_evidence is not None:
            entry["explanation"] += (f" ln Bayes factor over the model {c.delta_log_evidence:+.1f} +- "
                                     f"{c.delta_log_evidence_error:.1f}"
                                     + (" (the criterion here)." if criterion == "evidence" else "."))
        entry["posterior"] = posterior_quality(c.inversion)
        if not entry["posterior"]["converged"]:
            entry["explanation"] += (f" Its posterior {_unconverged(entry['posterior'])}: its delta ELPD-LOO is less "
                                     "certain than its SE says.")
        ranking.append(entry)
    for c in [c for c in screened if c not in to_confirm]:
        entry = {"effect": c.effect, "change": c.label, "delta_elpd": None, "delta_elpd_se": None, "rmse_dop_after": None,
                 "significant": False, "screening_gain": c.screening_gain,
                 "explanation": f"Screened out: its best fit gains only {c.screening_gain:.1f} in log posterior."}
        if c.dominated_by is not None:
            entry.update(dominated_by=c.dominated_by, delta_to_leader=-c.dominance_delta,
                         delta_to_leader_se=c.dominance_se, explanation=(
                f"Not refitted: its log likelihood at its best optimum (screening gain {c.screening_gain:.1f}) falls "
                f"below the refitted ELPD-LOO of '{c.dominated_by}' by {c.dominance_delta:.1f} +- {c.dominance_se:.1f}, "
                f"beyond 2 SE and any LOO correction ({c.dominance_margin:.0f}): it can neither lead nor tie."))
        if c.plugin_delta is not None:
            entry.update(plugin_delta=c.plugin_delta, plugin_se=c.plugin_se, explanation=(
                f"Not refitted: at the two optima its log likelihood differs from the model's by {c.plugin_delta:+.1f} "
                f"+- {c.plugin_se:.1f}, beyond 2 SE and any LOO correction ({c.plugin_margin:.0f}); significantly "
                f"{'better' if c.plugin_delta > 0 else 'worse'}."))
        ranking.append(entry)
    verdict = "none"
    if confirmed and confirmed[0].significant:
        lead = confirmed[0]
        verdict = lead.verdict
        tied = [c for c in confirmed[1:] if c.significant and _tied(lead, c)]
        if tied:
            ranking[0]["tied_with"] = [c.verdict for c in tied]
            for other in tied:
                sep = None
                if lead.kind == other.kind == "add":
                    sep = separating_measurement(lead.effect, other.effect)
                sep = sep or "a measurement in which they predict differently"
                ranking[0]["explanation"] += (f" It fits these data as well as '{other.label}' (equal within noise): the "
                                              f"two are twins here; {sep} would separate them.")
    for entry, c in zip(ranking, confirmed):
        entry["free_parameters"] = c.posterior.ndim
    return DiagnosisRecord({"model": model.name, "criterion": criterion, "fit": base.summary.fit, "base_posterior": posterior_quality(base),
            "ranking": ranking, "verdict": verdict,
            "not_screened": [{"change": c.label, "reason": BLIND_REASON} for c in blind],
            "free_parameters": base_post.ndim,
            "residual_structure": base.summary.residual_structure["findings"],
            "conclusion": _conclusion(base, confirmed, verdict),
            "seconds": {"base_fit": clock["base"] - clock["start"], "screening": clock["screening"] - clock["base"],
                        "confirmation": clock["confirmation"] - clock["screening"],
                        "leader_search": clock["leaders"] - clock["screening"],
                        "total": clock["confirmation"] - clock["start"], "candidates_screened": len(screened),
                        "candidates_refitted": len(confirmed)}},
                           base, confirmed)


def _same_posterior(result, posterior) -> bool:
    """Whether ``result`` (a Result or None) holds ``posterior`` itself: the same data object, model, observables and
    priors (a user's own run of the model, with its own priors or data, does not count)."""
    own = getattr(result, "posterior", None)
    if own is None:
        return False
    a, b = own.likelihood, posterior.likelihood
    return (a.data is b.data and model_key(a.model) == model_key(b.model) and a.observables == b.observables
            and own.priors.describe() == posterior.priors.describe())


def posterior_quality(inv) -> dict:
    """How a refit's posterior was obtained and whether it can be trusted (``Result.diagnostics``): the engine
    (laplace-is: trusted weights by construction; emcee: R-hat <= 1.01 and ESS >= 400, the targets a run waits for,
    else not converged within its cap, or ``stopped_early`` where its ELPD-LOO had settled: ``elpd_settled``; and
    ``laplace_refused``: why the Laplace approximation was not used, where it was tried)."""
    d = inv.diagnostics
    if d.engine == "laplace-is":
        return {"engine": d.engine, "converged": True, "pareto_k": d.pareto_k, "effective_draws": d.ess_min}
    quality = {"engine": d.engine, "converged": d.converged, "rhat_max": d.rhat_max, "ess_min": d.ess_min, "steps": d.steps,
               "stopped_early": bool(inv.summary.sampler.get("stopped_early", False))}
    if inv.summary.laplace_refused:
        quality["laplace_refused"] = inv.summary.laplace_refused
    return quality


def _unconverged(quality: dict) -> str:
    """``posterior_quality``'s figures for a chain that stopped short of its targets, in words."""
    text = f"did not converge ({quality['steps']} emcee steps, R-hat {quality['rhat_max']:.3f}, ESS {quality['ess_min']:.0f}"
    if quality.get("stopped_early"):
        text += f"; stopped where its two halves' ELPD-LOO agreed within {elpd_settled.TOLERANCE:g}"
    return text + ")"


# the standard error of a difference of pointwise log likelihoods at two optima, widened by this factor before it
# stands in for the LOO difference's (on PTFE's eight slot alternatives the LOO SE was 1.02-1.12 times it)
PLUGIN_SE_SLACK = 1.25


def _plugin_decides(c: CandidateFit, base_pointwise: np.ndarray, base_p_loo: float) -> bool:
    """Whether candidate ``c`` differs from the base so clearly that its refit cannot change the verdict: the pointwise
    log likelihood at its optimum minus the base's at the base's best draw (``base_pointwise``) sums to d with standard error s, and
    |d| - margin > 2 s x PLUGIN_SE_SLACK and > 4 + margin, margin = the base's p_loo + 2 x the candidate's free
    parameters (``base_p_loo``; ELPD-LOO = plug-in log likelihood - p_loo; the margin bounds the change in p_loo). On PTFE at 0.633 um
    (278 geometries, the eight slot alternatives of a five-effect model) the plug-in sums were within 17 of the
    refitted delta ELPD-LOO, whose p_loo changed by up to 26. Records the figures in ``c`` when it decides."""
    d = c.posterior.log_prob_pointwise(c.optimum[None, :])[0] - base_pointwise
    delta, se = float(d.sum()), float(np.sqrt(len(d) * np.var(d)))
    margin = base_p_loo + 2.0 * c.posterior.ndim
    if abs(delta) - margin > max(2.0 * PLUGIN_SE_SLACK * se, MIN_DELTA_ELPD):
        c.plugin_delta, c.plugin_se, c.plugin_margin = delta, se, margin
        return True
    return False


def _front_runner(refitted: list):
    """The refitted candidate a skipped one is weighed against: the best by ELPD-LOO, provided it is significant and
    its posterior converged (else None: an unconverged refit's ELPD is less certain than its SE says)."""
    best = max(refitted, key=lambda c: c.delta_elpd, default=None)
    if best is None or not best.significant or not posterior_quality(best.inversion)["converged"]:
        return None
    return best


def _dominated(c: CandidateFit, lead: CandidateFit) -> bool:
    """Whether candidate ``c`` is so clearly worse than the refitted ``lead`` that its refit could neither make it
    lead nor tie: the lead's pointwise ELPD-LOO minus c's pointwise log likelihood at its optimum sums to d with
    standard error s, and d - margin > 2 s x PLUGIN_SE_SLACK and > 4 + margin, margin = 2 x c's free parameters.
    The plug-in log likelihood stands above c's ELPD-LOO (by about its effective number of parameters, p_loo, for a
    regular posterior), so d understates how much worse c predicts; the margin covers a posterior whose LOO density
    exceeds its plug-in one. Its refit starts at the same optimum, so it would weigh the same mode.
    Records the figures in ``c`` when it decides."""
    d = lead.pointwise - c.posterior.log_prob_pointwise(c.optimum[None, :])[0]
    delta, se = float(d.sum()), float(np.sqrt(len(d) * np.var(d)))
    margin = 2.0 * c.posterior.ndim
    if delta - margin > max(2.0 * PLUGIN_SE_SLACK * se, MIN_DELTA_ELPD):
        c.dominance_delta, c.dominance_se, c.dominance_margin = delta, se, margin
        return True
    return False


def _say(text: str) -> None:
    print(f"  {text}", file=sys.stderr, flush=True)


def signatures(base, inv, base_fit=None) -> dict:
    """Per observable: the base fit's standardised residuals, and what the candidate changes in the
    prediction in the same noise units (its signature), their correlation and the share of the
    base chi^2 the candidate removes. ``base_fit``: the base's ``median_fit``, if already computed."""
    lik = base.posterior.likelihood
    mu0, scale = base_fit or median_fit(base.posterior, base.draws.flat_samples())
    mu1, _ = median_fit(inv.posterior, inv.draws.flat_samples())
    out = {}
    for o in base.posterior.likelihood.observables:
        observed = lik.standardise(o, mu0[o], scale[o])
        remaining = lik.standardise(o, mu1[o], scale[o])
        signature = observed - remaining
        corr = float(np.corrcoef(observed, signature)[0, 1]) if np.std(signature) > 0 and np.std(observed) > 0 else 0.0
        out[o] = {"observed": observed, "signature": signature, "correlation": corr,
                  "chi2_removed": float(1 - np.sum(remaining**2) / max(np.sum(observed**2), 1e-300))}
    return out


def _where(data, observed) -> str:
    """Where the base misfit is largest, in words."""
    worst = np.argsort(-np.abs(observed))[:max(3, len(observed) // 10)]
    tr, ti = data.theta_r[worst], data.theta_i[worst]
    return (f"theta_i {ti.min():.0f}-{ti.max():.0f} deg, theta_r {tr.min():.0f}-{tr.max():.0f} deg, "
            f"residuals mostly {'positive' if np.mean(observed[worst]) > 0 else 'negative'}")


MIN_DELTA_ELPD = 4.0


# Bayes factors: ln B > 3 (B > 20) is "strong" evidence on Kass & Raftery's scale (JASA 90, 773 (1995))
MIN_LOG_BAYES_FACTOR = 3.0
CRITERIA = ("loo", "evidence")


def significant_evidence(delta: float, error: float) -> bool:
    """A change the evidence favours: ln Bayes factor > 3 (strong, Kass & Raftery 1995) and > 2 x its error."""
    return bool(delta > MIN_LOG_BAYES_FACTOR and delta > 2 * error)


def evidence_of(result, posterior, seed: int) -> tuple[float, float]:
    """(ln Z, error) of a fit: its own where its engine gives one (Laplace-IS where its weights are trusted,
    nested sampling), else from the ``nested`` engine on the same posterior."""
    if result.log_evidence is not None:
        return result.log_evidence
    from ..infer.engine_registry import engines

    nested = engines.get("nested").result(posterior, seed=seed)
    result.summary.log_evidence = nested.summary.log_evidence
    return nested.log_evidence


def significant(delta: float, se: float) -> bool:
    """delta ELPD-LOO > 2 SE and > 4: below 4 the SE of a difference is unreliable and the models
    predict alike (Sivula, Magnusson & Vehtari 2020; Vehtari's cross-validation FAQ). Nested models
    on pure noise otherwise give tiny deltas with tinier SEs."""
    return bool(delta > 2 * se and delta > MIN_DELTA_ELPD)


def _close(a: float, b: float) -> bool:
    """Screening gains equal within the optimiser's reach (1 unit of log posterior, or 1 %)."""
    return abs(a - b) < 1.0 + 0.01 * max(abs(a), abs(b))


def _structured(summary: RunSummary) -> bool:
    """Residuals still carry structure: runs/trends flagged, or a misfit above the noise floor: with known noise
    chi^2 > 1.5; with inferred noise that the data also measure themselves, an inferred level above 1.5x the
    measured one; with inferred noise alone chi^2 ~ 1 by construction and says nothing."""
    if summary.noise:  # the data measure their noise: explained only within 1.5x of it
        return not explains(summary.noise) or summary.residual_structure["structured"]
    above_floor = not inferred_noise_levels(summary) and summary.fit["chi2_red"] > 1.5
    return above_floor or summary.residual_structure["structured"]


def _conclusion(base, confirmed, verdict) -> str:
    """One paragraph: what to add, and whether the library can explain what remains."""
    if verdict == "none":
        if _structured(base.summary):
            return ("No candidate in the library improves ELPD-LOO by more than 2 SE (and 4), yet the residuals of "
                    f"{base.summary.model} are structured ({describe_fit(base.summary)}; "
                    "see residual_structure): an effect outside the library is likely. Write it as a plug-in "
                    "effect and rerun diagnose.")
        return (f"No candidate improves ELPD-LOO by more than 2 SE (and 4), and the residuals of {base.summary.model} "
                "look like noise: nothing is missing at this noise level.")
    lead = next(c for c in confirmed if c.verdict == verdict)
    after = lead.inversion.summary
    text = f"{lead.label[0].upper()}{lead.label[1:]}: it is the change that improves ELPD-LOO most, by more than 2 SE."
    if _structured(after):
        text += (f" It helps, but does not explain the misfit (partly explained): after it the residuals are still "
                 f"structured ({describe_fit(after)}; " + " ".join(after.residual_structure["findings"])
                 + "). Run diagnose again on the changed model (or use --rounds); if nothing else in the library helps, "
                 "the rest comes from an effect outside it.")
    else:
        text += f" After it the residuals look like noise ({describe_fit(after)}): explained."
    return text


SAME_MISFIT = 0.8


def _tied(a, b) -> bool:
    """Two explanations of the same misfit that the data cannot tell apart: their signatures (what each
    changes in the prediction, in noise units) correlate >= 0.8, and neither is significantly better by
    the rule of ``significant`` (|delta ELPD| <= 2 SE of the difference, or <= 4; exact twins differ by
    sampling noise only; Sivula, Magnusson & Vehtari 2020). Changes that fix different parts of the
    misfit are not alternatives (the rounds take both), however close their ELPD.
    (A 1-SE rule without the signature split near-equals: on a rough dielectric render 'remove shadowing'
    +1202.5 and 'replace shadowing by smith' +1198.1 came out as a confident choice between them; a 2-SE
    rule alone tied 'remove shadowing' with 'add depolarization', which mend different misfits.)"""
    diff = a.pointwise - b.pointwise
    return (_signature_correlation(a, b) >= SAME_MISFIT
            and not significant(abs(float(diff.sum())), float(np.sqrt(len(diff) * np.var(diff)))))


def _signature_correlation(a, b) -> float:
    sa = np.concatenate([a.signatures[o]["signature"] for o in sorted(a.signatures)])
    sb = np.concatenate([b.signatures[o]["signature"] for o in sorted(b.signatures)])
    if np.std(sa) == 0 or np.std(sb) == 0:
        return 1.0 if np.std(sa) == np.std(sb) else 0.0
    return float(np.corrcoef(sa, sb)[0, 1])


def _explain(c: CandidateFit, base) -> str:
    cls = registry.get(c.effect)
    physics = _first_sentence(cls.description)
    if c.kind == "replace":
        physics = f"Replace {c.change.replaced} by {c.effect}: {physics}"
    elif c.kind == "remove":
        physics = f"Remove {c.effect} ({physics[0].lower()}{physics[1:]})"
    rmse0, rmse1 = base.summary.fit["rmse_dop"], c.rmse_dop_after
    rmse = f"RMSE(DOP) {rmse0:.4f} -> {rmse1:.4f}; " if rmse0 is not None and rmse1 is not None else ""
    noise0, noise1 = inferred_noise_levels(base.summary), inferred_noise_levels(c.inversion.summary)
    if noise0:
        rmse += "inferred noise " + ", ".join(f"{k} {noise0[k]:.3g} -> {noise1.get(k, float('nan')):.3g}" for k in noise0) + "; "
    verdict = "significant" if c.significant else "not significant (gain within 2 SE or below 4)"
    why = []
    data = base.posterior.likelihood.data
    for o, s in c.signatures.items():
        change = (f"removes {100 * s['chi2_removed']:.0f} % of their chi^2" if s["chi2_removed"] >= 0
                  else f"raises their chi^2 by {-100 * s['chi2_removed']:.0f} % (it trades this fit for another)")
        why.append(f"{o}: the base model misses most at {_where(data, s['observed'])}; this effect's signature "
                   f"correlates {s['correlation']:+.2f} with the residuals and {change}")
    bounds = [bound_finding(f) for f in c.inversion.summary.at_bound]
    if c.significant and _structured(c.inversion.summary):
        bounds.insert(0, "it helps, but does not explain the misfit: after it the residuals are still structured ("
                      + " ".join(c.inversion.summary.residual_structure["findings"]) + ").")
    return (f"{physics} Adding it changes ELPD-LOO by {c.delta_elpd:+.1f} +- {c.delta_elpd_se:.1f} ({verdict}); "
            f"{rmse}" + "; ".join(why) + "." + ("".join(f" Caution: {b}" for b in bounds)))
