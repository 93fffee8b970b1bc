"""diagnose --rounds N: accept the best significant change, continue from the changed model, stop when
no change is significant (or after N rounds).  The path records, per round, the model, the change, its
delta ELPD +- SE, the fit (reduced chi^2 with known noise; the inferred noise level otherwise) and the
residual structure, so a user sees the error fall round by round and whether the end is noise."""

from __future__ import annotations

import sys
from dataclasses import replace

import numpy as np

from ..infer.diagnostics import describe_fit, fit_words, inferred_noise_levels, misfit_words
from ..physics.model import Model
from .changes import changes, slot_alternatives
from .candidate_fits import CandidateFits
from .criteria import significant
from .diagnose import diagnose
from .explain import structured
from .records import CandidateFit, DiagnosisRecord, RoundStep, RoundsRecord, Rung
from ..infer.run_summary import RunSummary


def _step(summary: RunSummary, change=None, delta=None, se=None, tied=(), alternatives=(),
          simplification: bool | None = None) -> RoundStep:
    """The path's step to the model ``summary`` describes."""
    return RoundStep(summary.model, change, delta, se, tuple(tied), tuple(alternatives), summary.fit,
                     inferred_noise_levels(summary), summary.noise, tuple(summary.residual_findings),
                     bool(structured(summary)), tuple(summary.at_bound), simplification)


def as_rungs(result: RoundsRecord) -> list[Rung]:
    """The path as ladder rungs (for the ladder figure and table), with each round's Result."""
    inversions = [result.reports[0].base]
    for report, step in zip(result.reports, result["rounds"][1:]):
        inversions.append(next(c.inversion for c in report.confirmed if c.label == step["change"]))
    rungs = []
    for step, inv in zip(result["rounds"], inversions):
        fit = step["fit"]
        rungs.append(Rung({"model": step["model"], "change": step["change"], "delta_elpd": step["delta_elpd"],
                      "delta_elpd_se": step["delta_elpd_se"], "rmse_dop": fit["rmse_dop"], "chi2_red": fit["chi2_red"],
                      "elpd_loo": fit["elpd_loo"], "elpd_loo_se": fit["elpd_loo_se"], "inferred_noise": step["inferred_noise"],
                      "noise": step.get("noise", {}), "structured": step["structured"], "rhat_max": inv.summary.diagnostics["rhat_max"],
                      "pareto_k": inv.summary.diagnostics.get("pareto_k"),
                      "at_bound": step["at_bound"]}, inv))
    return rungs


def diagnose_rounds(data, model: Model, rng: np.random.Generator, rounds: int, seed: int = 0, observables=None,
                    candidates=None, top: int = 3, progress: bool = True, priors: dict | None = None, base=None,
                    posterior_method: str = "laplace", workers: int = 1, criterion: str = "loo") -> RoundsRecord:
    """The first round's report (DESIGN's fields) plus ``rounds`` (the path), ``final_model`` and a
    ``conclusion`` over the whole path; the record's ``reports`` keep each round's DiagnosisRecord. ``posterior_method``: how
    each fit's posterior is drawn (``candidate_fits.fit_for_elpd``); ``workers``: candidates fitted at once, in
    worker processes started once for all rounds; ``criterion``: ``loo`` or ``evidence`` (``diagnose``)."""
    with CandidateFits(data, observables, priors, workers) as fits:
        return _rounds(data, model, rng, rounds, seed, observables, candidates, top, progress, priors, base,
                       posterior_method, fits, criterion)


def _rounds(data, model, rng, rounds, seed, observables, candidates, top, progress, priors, base, posterior_method,
            fits, criterion="loo") -> RoundsRecord:
    reports, current = [], model
    path, slot_pass_seconds = [], None
    searched = {}  # the maxima found for each model screened so far (diagnose's ``searched``)
    for r in range(rounds):
        if progress:
            print(f"  round {r + 1}/{rounds}: what is missing from {current.name}?", file=sys.stderr, flush=True)
        report = diagnose(data, current, rng, seed=seed, observables=observables, candidates=candidates, top=top,
                          progress=progress, priors=priors, base=base, simplifications=2, posterior_method=posterior_method,
                          searched=searched, fits=fits, criterion=criterion)
        reports.append(report)
        if not path:
            path.append(_step(report.base.summary))
        simplification = None
        if report["verdict"] == "none":
            simplification = _simplification(report)
            if simplification is None:
                equivalent, better, slot_pass_seconds = _slot_equivalents(
                    data, current, rng, seed, observables, candidates, progress, priors, report.base, posterior_method,
                    searched, fits)
                path[-1] = replace(path[-1], equivalent=tuple(equivalent), better=tuple(better))
                break
        lead = simplification or next(c for c in report.confirmed if c.verdict == report["verdict"])
        # the other changes refitted in this round, so the path shows what the chosen one was weighed against
        alternatives = [{k: e[k] for k in ("change", "delta_elpd", "delta_elpd_se", "significant")}
                        for e in report["ranking"] if e["delta_elpd"] is not None and e["change"] != lead.label]
        path.append(_step(lead.inversion.summary, lead.label, lead.delta_elpd, lead.delta_elpd_se,
                          [] if simplification else report["ranking"][0].get("tied_with", []), alternatives,
                          simplification is not None))
        current, base = lead.model, lead.inversion
        if progress:
            print(f"  round {r + 1}: {lead.label} (delta ELPD {lead.delta_elpd:+.1f} +- {lead.delta_elpd_se:.1f}); "
                  f"{describe_fit(lead.inversion.summary)}", file=sys.stderr, flush=True)
    content = {**reports[0].to_json(), "rounds": path, "final_model": current.name,
               "conclusion_rounds": _conclusion(path, reports),
               # where each round's time went (``seconds`` above is the first round's), and the slot pass's
               "seconds_rounds": [r["seconds"] for r in reports], "seconds_slot_pass": slot_pass_seconds}
    return RoundsRecord(content, reports)


def _simplification(report: DiagnosisRecord) -> CandidateFit | None:
    """Where no change is significant: a refitted change with fewer free parameters that predicts as well
    (not significantly worse, the rule of ``significant``): the fewest parameters first, then the best ELPD."""
    base_ndim = report.base.posterior.ndim
    simpler = [c for c in report.confirmed if c.posterior.ndim < base_ndim
               and not significant(-c.delta_elpd, c.delta_elpd_se)]
    return min(simpler, key=lambda c: (c.posterior.ndim, -c.delta_elpd)) if simpler else None


def _slot_equivalents(data, model, rng, seed, observables, candidates, progress, priors, base,
                      posterior_method: str = "laplace", searched: dict | None = None,
                      fits=None) -> tuple[list[dict], list[dict], dict | None]:
    """Where the path stopped: refit every other member of each of the final model's slots (and the slot
    emptied), and keep those the data cannot tell from the member the model holds. One extra pass, so
    the conclusion can say which parts of the final model the data pin down. Returns (equivalent, better): the
    second, alternatives significantly better than the final model (the pass searches each globally, where the
    round's screening searched near the model and may have missed their best mode); and the pass's ``seconds`` (None
    where there was nothing to weigh)."""
    slots = {e.slot for e in model.effects if e.slot}
    labels = slot_alternatives(model, data, slots, candidates)
    if not labels:
        return [], [], None
    if progress:
        print(f"  the path stopped at {model.name}: weighing each slot's other members ({len(labels)} refits)",
              file=sys.stderr, flush=True)
    names = sorted({w for label in labels for w in label.split() if w not in ("add", "remove", "replace", "by")})
    # the user's prior overrides that concern these models (the others belong to effects not weighed here)
    known = set(base.posterior.names) | {p.name for c in changes(model, data, names) for p in c.model.parameters}
    report = diagnose(data, model, rng, seed=seed, observables=observables, candidates=names, top=0, progress=progress,
                      priors={k: v for k, v in (priors or {}).items() if k in known}, base=base, confirm=labels,
                      posterior_method=posterior_method, searched=searched, fits=fits)
    return _equivalent(report, labels), _better(report, labels), report["seconds"]


def _equivalent(report: DiagnosisRecord, labels) -> list[dict]:
    """Slot alternatives whose refit is not significantly better or worse than the final model: the data
    cannot tell which member fills that slot."""
    out = []
    for e in report["ranking"]:
        if e["change"] in labels and e["delta_elpd"] is not None and not significant(abs(e["delta_elpd"]), e["delta_elpd_se"]):
            out.append({k: e[k] for k in ("change", "delta_elpd", "delta_elpd_se")})
    return out


def _better(report: DiagnosisRecord, labels) -> list[dict]:
    """Slot alternatives significantly better than the final model: refitted (delta ELPD-LOO > 2 SE and > 4) or
    decided by their optima alone (``diagnose._plugin_decides``: the plug-in difference and its SE, flagged)."""
    out = []
    for e in report["ranking"]:
        if e["change"] not in labels:
            continue
        if e["delta_elpd"] is not None and e["significant"] and e["delta_elpd"] > 0:
            out.append({k: e[k] for k in ("change", "delta_elpd", "delta_elpd_se")} | {"plug_in": False})
        elif e.get("plugin_delta") is not None and e["plugin_delta"] > 0:
            out.append({"change": e["change"], "delta_elpd": e["plugin_delta"], "delta_elpd_se": e["plugin_se"],
                        "plug_in": True})
    return sorted(out, key=lambda e: -e["delta_elpd"])


def _conclusion(path: list[RoundStep], reports: list[DiagnosisRecord]) -> str:
    final = path[-1]
    changes = [p["change"] + (" (simpler, predicts as well)" if p.get("simplification") else "") for p in path[1:]]
    route = " -> ".join([path[0]["model"]] + changes) if changes else path[0]["model"]
    stopped = ("no further change is significant" if "equivalent" in final
               else f"the round limit was reached ({len(reports)})")
    if not changes:
        text = f"No change of {path[0]['model']} improves ELPD-LOO by more than 2 SE (and 4)."
    else:
        text = f"Path: {route}; {stopped}."
    fit = fit_words(final["fit"]["chi2_red"], final["inferred_noise"]) + misfit_words(final.get("noise"))
    if final["structured"]:
        text += (f" Partly explained: the final model {final['model']} still leaves structured residuals ({fit}; "
                 + " ".join(final["residual_structure"]) + "). The structure that remains points to an effect the library "
                 "does not have (or one the rounds did not reach).")
    else:
        text += f" Explained: the residuals of the final model {final['model']} look like noise ({fit})."
    if final.get("better"):
        text += (" But the last pass, which searched each slot alternative globally, found changes significantly better "
                 "than the final model: " + ", ".join(
                     f"{e['change']} ({e['delta_elpd']:+.1f} +- {e['delta_elpd_se']:.1f}"
                     + (", from the two optima" if e["plug_in"] else "") + ")" for e in final["better"])
                 + ". The rounds' screening, which searches near the current model, missed that mode: start again from "
                   "the changed model (diagnose --model).")
    if final.get("equivalent"):
        text += (" The data cannot tell the final model from these slot alternatives (neither significantly better): "
                 + ", ".join(f"{e['change']} ({e['delta_elpd']:+.1f} +- {e['delta_elpd_se']:.1f})" for e in final["equivalent"]) + ".")
    return text
