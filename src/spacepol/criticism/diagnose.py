"""Which physical effect is missing: screen every registered effect, confirm the leaders.

1. Fit the model M (emcee) and keep its pointwise PSIS-LOO.
2. Screening: for every registered effect E not in M (built-in or plug-in) that composes with
   M, a quick differential-evolution maximum of the log posterior of M + E; the gain over M's
   maximum (a likelihood-ratio statistic) ranks the candidates.
3. Confirmation: the ``top`` candidates are refitted with emcee; the change in ELPD-LOO and its
   standard error come from the pointwise LOO differences; significant = gain > 2 SE and > 4.
4. Twins: confirmed candidates whose pointwise LOO agree within noise (difference < 1 SE) are
   reported as tied; the explanation says what measurement separates them.
"""

from __future__ import annotations

import re
import sys
import time

import numpy as np

from ..errors import SpacepolError
from ..infer.diagnostics import describe_fit, inferred_noise_levels
from ..infer.identifiability import bound_finding
from ..infer.inference_data import median_fit, standardise
from ..infer.inversion import invert
from ..infer.optimum import find_optimum
from ..infer.posterior import Posterior
from ..physics.model import Model
from ..physics.registry import registry

SEPARATING_MEASUREMENT = {
    frozenset({"extinction", "depolarization"}): "the full Mueller matrix (an analyser acts on the detector side only, "
    "depolarization on the light itself: M01 and M10 differ)",
}


def _first_sentence(text: str) -> str:
    return re.split(r"(?<!et al)(?<!e\.g)(?<!i\.e)\.\s+(?=[A-Z])", text)[0].rstrip(".") + "."


def _candidates(model: Model, data, names=None):
    out = []
    for name in names or registry.names():
        if name in [e.name for e in model.effects]:
            continue
        try:
            candidate = model + name
        except SpacepolError:
            continue  # does not compose with M (e.g. smith with shadowing)
        if name == "oxide_layer" and (data.wavelength_um is None or np.any(~np.isfinite(data.wavelength_um))):
            continue
        out.append((name, candidate))
    return out


def _build(data, model, observables, priors):
    """The posterior of ``model`` with those prior overrides that name its parameters (or nuisances)."""
    probe = Posterior.build(data, model, observables=observables)
    own = {p.name for p in probe.priors.parameters}
    return Posterior.build(data, model, {k: v for k, v in (priors or {}).items() if k in own}, observables=observables)


def check_prior_names(data, model: Model, priors: dict, observables=None, candidates=None) -> None:
    """Every overridden prior must belong to the base model or to one of the candidates."""
    known = {p.name for p in Posterior.build(data, model, observables=observables).priors.parameters}
    for _, candidate in _candidates(model, data, candidates):
        known |= {p.name for p in candidate.parameters}
    unknown = sorted(set(priors or {}) - known)
    if unknown:
        raise SpacepolError(f"--prior: no parameter(s) {', '.join(unknown)} in {model.name} or any candidate effect")


def _screen(posterior, rng, budget, seeds=None):
    value, theta = find_optimum(posterior, rng, evaluations=budget, seeds=seeds)
    return value, dict(zip(posterior.priors.names, theta))


def _vector(values: dict, posterior) -> np.ndarray:
    return np.array([values[n] for n in posterior.priors.names], float)


def nested_seeds(base_best: dict, candidate, posterior) -> np.ndarray:
    """Start points of M + E at M's optimum: E's own parameters at their prior's lower end, default,
    upper end and middle (most effects vanish at one of them: rho_pd = 0, e = 1, delta = 0, ...);
    a parameter that splits one of M's (sigma -> sigma_x, sigma_y) starts at its value."""
    params = {p.name: p for p in candidate.parameters}
    rows = []
    for option in range(4):
        row = []
        for name in posterior.priors.names:
            if name in base_best:
                row.append(base_best[name])
                continue
            split = [r for r in base_best if name.startswith(r + "_")]
            lo, hi = posterior.priors.priors[name].bounds
            default = params[name].default if name in params else 0.5 * (lo + hi)
            row.append(base_best[split[0]] if split else [lo, default, hi, 0.5 * (lo + hi)][option])
        rows.append(row)
    return np.clip(np.array(rows), posterior.priors.bounds[:, 0], posterior.priors.bounds[:, 1])


def diagnose(data, model: Model, rng: np.random.Generator, seed: int = 0, observables=None, candidates=None,
             top: int = 3, screening_evaluations: int = 4000, max_steps: int = 8000, progress: bool = True,
             priors: dict | None = None, base=None) -> dict:
    """Rank the effects missing from ``model``; ``priors`` overrides default priors by parameter name;
    ``base``: an Inversion of ``model`` on these data already at hand (it is not refitted)."""
    check_prior_names(data, model, priors, observables, candidates)
    clock = {"start": time.perf_counter()}
    base_post = _build(data, model, observables, priors)
    base_best, base_optimum = _screen(base_post, rng, screening_evaluations)
    all_candidates = _candidates(model, data, candidates)
    if base is None:
        if progress:
            _say(f"[base] fitting {model.name} with emcee ({len(data)} geometries) ...")
        base = invert(base_post, seed=seed, max_steps=max_steps, progress=False, centre=_vector(base_optimum, base_post))
    base_loo = base.loo["pointwise"]
    base_fit = median_fit(base.posterior, base.result.flat_samples())
    clock["base"] = time.perf_counter()

    if progress:
        _say(f"[base] done in {clock['base'] - clock['start']:.0f} s; screening {len(all_candidates)} candidate effects")
    screened = []
    for i, (name, candidate) in enumerate(all_candidates, start=1):
        post = _build(data, candidate, observables, priors)
        best, optimum = _screen(post, rng, screening_evaluations, seeds=nested_seeds(base_optimum, candidate, post))
        gain = best - base_best
        screened.append({"effect": name, "model": candidate, "posterior": post, "screening_gain": float(gain),
                         "optimum": _vector(optimum, post)})
        if progress:
            _say(f"[screen {i}/{len(all_candidates)}] {name:<18s} max log posterior gain {gain:9.2f} "
                 f"({time.perf_counter() - clock['start']:.0f} s)")
    screened.sort(key=lambda c: -c["screening_gain"])

    clock["screening"] = time.perf_counter()
    # a candidate whose screening gain equals the leader's may be its twin: confirm it too
    to_confirm = screened[:top] + [c for c in screened[top:] if screened and _close(c["screening_gain"], screened[0]["screening_gain"])]
    confirmed = []
    for i, c in enumerate(to_confirm, start=1):
        if progress:
            _say(f"[confirm {i}/{len(to_confirm)}] {c['effect']}: emcee posterior and PSIS-LOO "
                 f"({time.perf_counter() - clock['start']:.0f} s)")
        # start at the screening optimum: multimodal candidates (film thickness) keep the mode screening found
        inv = invert(c["posterior"], seed=seed, max_steps=max_steps, progress=False, centre=c["optimum"])
        diff = inv.loo["pointwise"] - base_loo
        c.update(inversion=inv, pointwise=inv.loo["pointwise"], delta_elpd=float(diff.sum()),
                 delta_elpd_se=float(np.sqrt(len(diff) * np.var(diff))),
                 rmse_dop_after=inv.summary["fit"]["rmse_dop"], signatures=signatures(base, inv, base_fit))
        c["significant"] = significant(c["delta_elpd"], c["delta_elpd_se"])
        confirmed.append(c)
    confirmed.sort(key=lambda c: -c["delta_elpd"])
    clock["confirmation"] = time.perf_counter()

    ranking = []
    for i, c in enumerate(confirmed):
        entry = {k: c[k] for k in ("effect", "delta_elpd", "delta_elpd_se", "rmse_dop_after", "significant")}
        entry["screening_gain"] = c["screening_gain"]
        entry["explanation"] = _explain(c, base)
        ranking.append(entry)
    for c in screened[len(to_confirm):]:
        ranking.append({"effect": c["effect"], "delta_elpd": None, "delta_elpd_se": None, "rmse_dop_after": None,
                        "significant": False, "screening_gain": c["screening_gain"],
                        "explanation": f"Screened out: its best fit gains only {c['screening_gain']:.1f} in log posterior."})
    verdict = "none"
    if confirmed and confirmed[0]["significant"]:
        lead = confirmed[0]
        verdict = lead["effect"]
        tied = [c["effect"] for c in confirmed[1:] if c["significant"] and _tied(lead, c)]
        if tied:
            ranking[0]["tied_with"] = tied
            for other in tied:
                sep = SEPARATING_MEASUREMENT.get(frozenset({lead["effect"], other}), "a measurement in which they predict differently")
                ranking[0]["explanation"] += (f" It fits these data as well as {other} (equal within noise): the two are twins "
                                              f"here; {sep} would separate them.")
    return {"model": model.name, "fit": base.summary["fit"], "ranking": ranking, "verdict": verdict,
            "residual_structure": base.summary["residual_structure"]["findings"],
            "conclusion": _conclusion(base, confirmed, verdict),
            "seconds": {"base_fit": clock["base"] - clock["start"], "screening": clock["screening"] - clock["base"],
                        "confirmation": clock["confirmation"] - clock["screening"],
                        "total": clock["confirmation"] - clock["start"], "candidates_screened": len(screened),
                        "candidates_refitted": len(confirmed)},
            "_base": base, "_confirmed": confirmed}


def _say(text: str) -> None:
    print(f"  {text}", file=sys.stderr, flush=True)


def signatures(base, inv, base_fit=None) -> dict:
    """Per observable: the base fit's standardised residuals, and what the candidate changes in the
    prediction in the same noise units (its signature), their correlation and the share of the
    base chi^2 the candidate removes. ``base_fit``: the base's ``median_fit``, if already computed."""
    data = base.posterior.likelihood.data
    mu0, scale = base_fit or median_fit(base.posterior, base.result.flat_samples())
    mu1, _ = median_fit(inv.posterior, inv.result.flat_samples())
    out = {}
    for o in base.posterior.likelihood.observables:
        observed = standardise(data, o, mu0[o], scale[o])
        remaining = standardise(data, o, mu1[o], scale[o])
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


def significant(delta: float, se: float) -> bool:
    """delta ELPD-LOO > 2 SE and > 4: below 4 the SE of a difference is unreliable and the models
    predict alike (Sivula, Magnusson & Vehtari 2020; Vehtari's cross-validation FAQ). Nested models
    on pure noise otherwise give tiny deltas with tinier SEs."""
    return bool(delta > 2 * se and delta > MIN_DELTA_ELPD)


def _close(a: float, b: float) -> bool:
    """Screening gains equal within the optimiser's reach (1 unit of log posterior, or 1 %)."""
    return abs(a - b) < 1.0 + 0.01 * max(abs(a), abs(b))


def _structured(summary) -> bool:
    """Residuals still carry structure: runs/trends flagged, or (with known noise only) a misfit above
    the noise floor; with inferred noise chi^2 ~ 1 by construction and says nothing."""
    above_floor = not inferred_noise_levels(summary) and summary["fit"]["chi2_red"] > 1.5
    return above_floor or summary["residual_structure"]["structured"]


def _conclusion(base, confirmed, verdict) -> str:
    """One paragraph: what to add, and whether the library can explain what remains."""
    if verdict == "none":
        if _structured(base.summary):
            return ("No candidate in the library improves ELPD-LOO by more than 2 SE (and 4), yet the residuals of "
                    f"{base.summary['model']} are structured ({describe_fit(base.summary)}; "
                    "see residual_structure): an effect outside the library is likely. Write it as a plug-in "
                    "effect and rerun diagnose.")
        return (f"No candidate improves ELPD-LOO by more than 2 SE (and 4), and the residuals of {base.summary['model']} "
                "look like noise: nothing is missing at this noise level.")
    after = next(c for c in confirmed if c["effect"] == verdict)["inversion"].summary
    text = f"Add {verdict}: it is the candidate that improves ELPD-LOO most, by more than 2 SE."
    if _structured(after):
        text += (f" After adding it the residuals are still structured ({describe_fit(after)}"
                 + "; " + " ".join(after["residual_structure"]["findings"])
                 + "): run diagnose again on the extended model; if nothing else in the library helps, the rest comes "
                 "from an effect outside it.")
    else:
        text += f" After adding it the residuals look like noise ({describe_fit(after)})."
    return text


def _tied(a, b) -> bool:
    """Equal predictive performance within noise: |delta ELPD| below 1 SE of the difference, or below 4
    (exact twins differ by sampling noise only, whose sum is small in absolute terms but not in SE
    units; Sivula, Magnusson & Vehtari 2020)."""
    diff = a["pointwise"] - b["pointwise"]
    return abs(diff.sum()) < max(np.sqrt(len(diff) * np.var(diff)), MIN_DELTA_ELPD)


def _explain(c, base) -> str:
    cls = registry.get(c["effect"])
    physics = _first_sentence(cls.description)
    rmse0, rmse1 = base.summary["fit"]["rmse_dop"], c["rmse_dop_after"]
    rmse = f"RMSE(DOP) {rmse0:.4f} -> {rmse1:.4f}; " if rmse0 is not None and rmse1 is not None else ""
    noise0, noise1 = inferred_noise_levels(base.summary), inferred_noise_levels(c["inversion"].summary)
    if noise0:
        rmse += "inferred noise " + ", ".join(f"{k} {noise0[k]:.3g} -> {noise1.get(k, float('nan')):.3g}" for k in noise0) + "; "
    verdict = "significant" if c["significant"] else "not significant (gain within 2 SE or below 4)"
    why = []
    data = base.posterior.likelihood.data
    for o, s in c["signatures"].items():
        change = (f"removes {100 * s['chi2_removed']:.0f} % of their chi^2" if s["chi2_removed"] >= 0
                  else f"raises their chi^2 by {-100 * s['chi2_removed']:.0f} % (it trades this fit for another)")
        why.append(f"{o}: the base model misses most at {_where(data, s['observed'])}; this effect's signature "
                   f"correlates {s['correlation']:+.2f} with the residuals and {change}")
    bounds = [bound_finding(f) for f in c["inversion"].summary["identifiability"].get("at_bound", [])]
    return (f"{physics} Adding it changes ELPD-LOO by {c['delta_elpd']:+.1f} +- {c['delta_elpd_se']:.1f} ({verdict}); "
            f"{rmse}" + "; ".join(why) + "." + ("".join(f" Caution: {b}" for b in bounds)))
