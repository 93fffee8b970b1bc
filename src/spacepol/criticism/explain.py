"""How diagnose puts what it found into words: each change's signature (what it changes in the prediction, in
noise units), ties between changes that mend the same misfit, whether residuals are still structured, how far a
refit's posterior can be trusted, and the explanation and conclusion a diagnosis reports."""

from __future__ import annotations

import re
from dataclasses import replace

import numpy as np

from ..infer import elpd_settled
from ..infer.diagnostics import describe_fit, inferred_noise_levels
from ..infer.draws_result import explains
from ..infer.identifiability import bound_finding
from ..infer.inference_data import median_fit
from ..infer.run_summary import RunSummary
from ..physics.registry import registry
from .changes import separating_measurement
from .criteria import significant
from .records import RankingEntry


def _first_sentence(text: str) -> str:
    return re.split(r"(?<!et al)(?<!e\.g)(?<!i\.e)\.\s+(?=[A-Z])", text)[0].rstrip(".") + "."

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


def unconverged_words(quality: dict) -> str:
    """``posterior_quality``'s figures for a chain that stopped short of its targets, in words."""
    text = f"did not converge ({quality['steps']} emcee steps, R-hat {quality['rhat_max']:.3f}, ESS {quality['ess_min']:.0f}"
    if quality.get("stopped_early"):
        text += f"; stopped where its two halves' ELPD-LOO agreed within {elpd_settled.TOLERANCE:g}"
    return text + ")"

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


def structured(summary: RunSummary) -> bool:
    """Residuals still carry structure: runs/trends flagged, or a misfit above the noise floor: with known noise
    chi^2 > 1.5; with inferred noise that the data also measure themselves, an inferred level above 1.5x the
    measured one; with inferred noise alone chi^2 ~ 1 by construction and says nothing."""
    if summary.noise:  # the data measure their noise: explained only within 1.5x of it
        return not explains(summary.noise) or summary.residuals_structured
    above_floor = not inferred_noise_levels(summary) and summary.fit["chi2_red"] > 1.5
    return above_floor or summary.residuals_structured


def conclusion(base, confirmed, verdict) -> str:
    """One paragraph: what to add, and whether the library can explain what remains."""
    if verdict == "none":
        if structured(base.summary):
            return ("No candidate in the library improves ELPD-LOO by more than 2 SE (and 4), yet the residuals of "
                    f"{base.summary.model} are structured ({describe_fit(base.summary)}; "
                    "see residual_structure): an effect outside the library is likely. Write it as a plug-in "
                    "effect and rerun diagnose.")
        return (f"No candidate improves ELPD-LOO by more than 2 SE (and 4), and the residuals of {base.summary.model} "
                "look like noise: nothing is missing at this noise level.")
    lead = next(c for c in confirmed if c.verdict == verdict)
    after = lead.inversion.summary
    text = f"{lead.label[0].upper()}{lead.label[1:]}: it is the change that improves ELPD-LOO most, by more than 2 SE."
    if structured(after):
        text += (f" It helps, but does not explain the misfit (partly explained): after it the residuals are still "
                 f"structured ({describe_fit(after)}; " + " ".join(after.residual_findings)
                 + "). Run diagnose again on the changed model (or use --rounds); if nothing else in the library helps, "
                 "the rest comes from an effect outside it.")
    else:
        text += f" After it the residuals look like noise ({describe_fit(after)}): explained."
    return text

SAME_MISFIT = 0.8


def tied(a, b) -> bool:
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

def explain_change(c, base) -> str:
    """What a refitted change does, in words: its physics, its delta ELPD-LOO with SE, the RMSE and noise before and
    after, which observables, elements and angles it mends (its signature against the base's residuals), and
    cautions (parameters at a bound, residuals still structured)."""
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
    if c.significant and structured(c.inversion.summary):
        bounds.insert(0, "it helps, but does not explain the misfit: after it the residuals are still structured ("
                      + " ".join(c.inversion.summary.residual_findings) + ").")
    return (f"{physics} Adding it changes ELPD-LOO by {c.delta_elpd:+.1f} +- {c.delta_elpd_se:.1f} ({verdict}); "
            f"{rmse}" + "; ".join(why) + "." + ("".join(f" Caution: {b}" for b in bounds)))


def posterior_words(inv) -> str:
    """How a refit's posterior was drawn, in a progress line."""
    q = posterior_quality(inv)
    if q["engine"] == "laplace-is":
        return "Laplace-IS"
    refused = f": {q['laplace_refused']}" if q.get("laplace_refused") else ""
    return (f"emcee (the Laplace approximation was not trusted{refused})"
            + ("" if q["converged"] else f", which {unconverged_words(q)}"))


def refitted_entry(c, base, note: str) -> RankingEntry:
    """A refitted change's ranking entry: both differences where known, its explanation and posterior quality."""
    explanation = explain_change(c, base)
    if c.delta_log_evidence is not None:
        explanation += (f" ln Bayes factor over the model {c.delta_log_evidence:+.1f} +- "
                        f"{c.delta_log_evidence_error:.1f}" + note)
    quality = posterior_quality(c.inversion)
    if not quality["converged"]:
        explanation += (f" Its posterior {unconverged_words(quality)}: its delta ELPD-LOO is less certain than its SE "
                        "says.")
    return RankingEntry(c.effect, c.label, c.screening_gain, explanation, refitted=True, delta_elpd=c.delta_elpd,
                        delta_elpd_se=c.delta_elpd_se, rmse_dop_after=c.rmse_dop_after, significant=c.significant,
                        delta_log_evidence=c.delta_log_evidence, delta_log_evidence_error=c.delta_log_evidence_error,
                        explains_misfit=not structured(c.inversion.summary), posterior=quality,
                        free_parameters=c.posterior.ndim)


def unrefitted_entry(c) -> RankingEntry:
    """A change screened out, dominated by the refitted leader, or decided by its optimum alone."""
    if c.plugin_delta is not None:
        return RankingEntry(c.effect, c.label, c.screening_gain, (
            f"Not refitted: at the two optima its log likelihood differs from the model's by {c.plugin_delta:+.1f} "
            f"+- {c.plugin_se:.1f}, beyond 2 SE and any LOO correction ({c.plugin_margin:.0f}); significantly "
            f"{'better' if c.plugin_delta > 0 else 'worse'}."), plugin_delta=c.plugin_delta, plugin_se=c.plugin_se,
            **_dominance(c))
    if c.dominated_by is not None:
        return RankingEntry(c.effect, c.label, c.screening_gain, (
            f"Not refitted: its log likelihood at its best optimum (screening gain {c.screening_gain:.1f}) falls "
            f"below the refitted ELPD-LOO of '{c.dominated_by}' by {c.dominance_delta:.1f} +- {c.dominance_se:.1f}, "
            f"beyond 2 SE and any LOO correction ({c.dominance_margin:.0f}): it can neither lead nor tie."),
            **_dominance(c))
    return RankingEntry(c.effect, c.label, c.screening_gain,
                        f"Screened out: its best fit gains only {c.screening_gain:.1f} in log posterior.")


def _dominance(c) -> dict:
    """The fields of a change the refitted leader dominates (none where it is not dominated)."""
    if c.dominated_by is None:
        return {}
    return {"dominated_by": c.dominated_by, "delta_to_leader": -c.dominance_delta, "delta_to_leader_se": c.dominance_se}


def tie_words(entry: RankingEntry, confirmed: list) -> RankingEntry:
    """The leader's entry, naming the significant changes tied with it and the measurement that would separate them."""
    lead = confirmed[0]
    ties = [c for c in confirmed[1:] if c.significant and tied(lead, c)]
    explanation = entry.explanation
    for other in ties:
        sep = separating_measurement(lead.effect, other.effect) if lead.kind == other.kind == "add" else None
        sep = sep or "a measurement in which they predict differently"
        explanation += (f" It fits these data as well as '{other.label}' (equal within noise): the two are twins "
                        f"here; {sep} would separate them.")
    return replace(entry, tied_with=tuple(c.verdict for c in ties), explanation=explanation)
