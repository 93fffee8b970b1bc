"""Which physical effect is missing: screen every registered effect, confirm the leaders.

1. Fit the model M (emcee) and keep its pointwise PSIS-LOO.
2. Screening: for every registered effect E not in M (built-in or plug-in) that composes with
   M, a quick differential-evolution maximum of the log posterior of M + E; the gain over M's
   maximum (a likelihood-ratio statistic) ranks the candidates.
3. Confirmation: the ``top`` candidates are refitted with emcee; the change in ELPD-LOO and its
   standard error come from the pointwise LOO differences; significant = gain > 2 SE.
4. Twins: confirmed candidates whose pointwise LOO agree within noise (difference < 1 SE) are
   reported as tied; the explanation says what measurement separates them.
"""

from __future__ import annotations

import numpy as np

from ..errors import SpacepolError
from ..infer.diagnostics import loo
from ..infer.engines.de import run_de
from ..infer.inference_data import to_inference_data
from ..infer.inversion import invert
from ..infer.objective import NegativeLogPosterior
from ..infer.posterior import Posterior
from ..physics.model import Model
from ..physics.registry import registry

SEPARATING_MEASUREMENT = {
    frozenset({"extinction", "depolarization"}): "the full Mueller matrix (an analyser acts on the detector side only, "
    "depolarization on the light itself: M01 and M10 differ)",
}


def _first_sentence(text: str) -> str:
    return text.split(". ")[0].rstrip(".") + "."


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


def _screen(posterior, rng, budget):
    res = run_de(NegativeLogPosterior(posterior), rng, max_evaluations=budget, popsize=10, polish=True)
    return -res.objective


def diagnose(data, model: Model, rng: np.random.Generator, seed: int = 0, observables=None, candidates=None,
             top: int = 3, screening_evaluations: int = 4000, max_steps: int = 8000, progress: bool = True) -> dict:
    base_post = Posterior.build(data, model, observables=observables)
    if progress:
        print(f"  fitting {model.name} ...", flush=True)
    base = invert(base_post, seed=seed, max_steps=max_steps, progress=False)
    base_loo = base.loo["pointwise"]
    base_best = _screen(base_post, rng, screening_evaluations)

    screened = []
    for name, candidate in _candidates(model, data, candidates):
        post = Posterior.build(data, candidate, observables=observables)
        gain = _screen(post, rng, screening_evaluations) - base_best
        screened.append({"effect": name, "model": candidate, "posterior": post, "screening_gain": float(gain)})
        if progress:
            print(f"  screening {name:<18s} max log posterior gain {gain:9.2f}", flush=True)
    screened.sort(key=lambda c: -c["screening_gain"])

    confirmed = []
    for c in screened[:top]:
        if progress:
            print(f"  confirming {c['effect']} with emcee ...", flush=True)
        inv = invert(c["posterior"], seed=seed, max_steps=max_steps, progress=False)
        diff = inv.loo["pointwise"] - base_loo
        c.update(inversion=inv, pointwise=inv.loo["pointwise"], delta_elpd=float(diff.sum()),
                 delta_elpd_se=float(np.sqrt(len(diff) * np.var(diff))),
                 rmse_dop_after=inv.summary["fit"]["rmse_dop"])
        c["significant"] = bool(c["delta_elpd"] > 2 * c["delta_elpd_se"] and c["delta_elpd"] > 0)
        confirmed.append(c)
    confirmed.sort(key=lambda c: -c["delta_elpd"])

    ranking = []
    for i, c in enumerate(confirmed):
        entry = {k: c[k] for k in ("effect", "delta_elpd", "delta_elpd_se", "rmse_dop_after", "significant")}
        entry["screening_gain"] = c["screening_gain"]
        entry["explanation"] = _explain(c, base)
        ranking.append(entry)
    for c in screened[top:]:
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
            "_base": base, "_confirmed": confirmed}


def _tied(a, b) -> bool:
    diff = a["pointwise"] - b["pointwise"]
    return abs(diff.sum()) < np.sqrt(len(diff) * np.var(diff))


def _explain(c, base) -> str:
    cls = registry.get(c["effect"])
    physics = _first_sentence(cls.description)
    rmse0, rmse1 = base.summary["fit"]["rmse_dop"], c["rmse_dop_after"]
    change = f"RMSE(DOP) {rmse0:.4f} -> {rmse1:.4f}; " if rmse0 is not None and rmse1 is not None else ""
    verdict = "significant" if c["significant"] else "not significant (gain within 2 SE)"
    return (f"{physics} Adding it changes ELPD-LOO by {c['delta_elpd']:+.1f} +- {c['delta_elpd_se']:.1f} ({verdict}); "
            f"{change}")
