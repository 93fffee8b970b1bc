"""Files of ``invert-mcmc diagnose``: residual figures, the signature figure, report.html."""

from __future__ import annotations

from pathlib import Path

from ..infer.diagnostics import describe_fit, fit_words
from ..infer.identifiability import bound_finding
from ..io.atomic import atomic_path, save_figure
from . import html as H
from ..infer.residuals import analyse
from .criticism_figures import ladder_figure, residual_trends_figure, signature_figure
from .ladder_report import ladder_table
from .inversion_figures import residual_figure
from ..infer.run_summary import RunSummary


def pareto_warnings(summary: RunSummary) -> list[str]:
    """Sentences for the fits whose PSIS-LOO has observations with Pareto k above 0.7."""
    bad = summary.pareto_k_bad
    if not bad:
        return []
    return [f"PSIS-LOO is unreliable (Pareto k > 0.7) at {len(bad)} point(s), where the fit hinges on single "
            f"observations: {', '.join(bad[:10])}{' ...' if len(bad) > 10 else ''}. Their ELPD terms, and deltas "
            "that rest on them, carry more error than the SE says."]


def ranking_rows(report: dict) -> list[list]:
    """The ranking as table rows (change, delta ELPD and its SE, significance, how the refit's posterior was obtained)."""
    rows = []
    for r in report["ranking"]:
        confirmed = r["delta_elpd"] is not None
        rows.append([r.get("change", r["effect"]), f"{r['screening_gain']:+.1f}",
                     f"{r['delta_elpd']:+.1f} +- {r['delta_elpd_se']:.1f}" if confirmed else "not refitted",
                     f"{r['rmse_dop_after']:.4f}" if confirmed and r["rmse_dop_after"] is not None else "",
                     ("yes" if r["significant"] else "no") + (f" (tied with {', '.join(r['tied_with'])})" if r.get("tied_with") else "")])
    return rows


def _name(entry: dict) -> str:
    """An addition by its effect's name (as before swaps existed), any other change in words."""
    change = entry.get("change") or f"add {entry['effect']}"
    return entry["effect"] if change == f"add {entry['effect']}" else change


def figure_name(change_label: str) -> str:
    """A file name for a change's residual figure."""
    words = change_label.split()
    return f"residuals_{words[1]}.png" if words[0] == "add" else "residuals_" + "_".join(words) + ".png"


def significance_statement(report: dict) -> str:
    """Which candidates improve ELPD-LOO by more than 2 SE and which do not, in one sentence."""
    confirmed = [r for r in report["ranking"] if r["delta_elpd"] is not None]
    yes = [f"{_name(r)} ({r['delta_elpd']:+.1f} +- {r['delta_elpd_se']:.1f})" for r in confirmed if r["significant"]]
    no = [f"{_name(r)} ({r['delta_elpd']:+.1f} +- {r['delta_elpd_se']:.1f})" for r in confirmed if not r["significant"]]
    screened = [_name(r) for r in report["ranking"] if r["delta_elpd"] is None and not r.get("dominated_by")]
    worse = [f"{_name(r)} ({r['delta_to_leader']:+.1f} +- {r['delta_to_leader_se']:.1f} below {r['dominated_by']})"
             for r in report["ranking"] if r["delta_elpd"] is None and r.get("dominated_by")]
    text = ("Improve ELPD-LOO by more than 2 SE: " + (", ".join(yes) if yes else "none") + ". Do not: "
            + (", ".join(no) if no else "none of the refitted candidates"))
    if worse:
        text += "; not refitted, clearly worse than a refitted change at their own optimum: " + ", ".join(worse)
    if screened:
        text += "; screened out before refitting (their best fit gains too little): " + ", ".join(screened)
    blind = [e["change"] for e in report.get("not_screened", [])]
    if blind:
        text += ("; not screened, since they change only the measured DOP, which none of the fitted observables reads: "
                 + ", ".join(blind))
    return text + "."


def write_diagnose_report(report: dict, base, confirmed: list, out: Path, data_label: str,
                          path_rungs: list | None = None) -> dict[str, Path]:
    """Write the figures and report.html into ``out``; returns the figure paths. ``path_rungs``: the
    rounds of `diagnose --rounds` as ladder rungs (a path section, ``path.png`` and ``path.md``)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    paths = {"base": out / "residuals_base.png", "signatures": out / "signatures.png"}
    save_figure(residual_figure(base.posterior, base.draws), paths["base"])
    paths["trends"] = out / "residual_trends_base.png"
    save_figure(residual_trends_figure(analyse(base.posterior, base.draws.flat_samples())), paths["trends"])
    for c in confirmed:
        paths[c.label] = out / figure_name(c.label)
        save_figure(residual_figure(c.inversion.posterior, c.inversion.draws), paths[c.label])
    labels = [_name({"change": c.label, "effect": c.effect}) for c in confirmed]
    save_figure(signature_figure(base, [(label, c.signatures) for label, c in zip(labels, confirmed)]), paths["signatures"])
    fit = report["fit"]
    sections = [
        ("Data and base model", H.paragraph(
            f"{data_label}; base model {report['model']}: RMSE(DOP) {fit['rmse_dop'] if fit['rmse_dop'] is None else round(fit['rmse_dop'], 5)}, "
            f"{describe_fit(base.summary)}, ELPD-LOO {fit['elpd_loo']:.1f} +- {fit['elpd_loo_se']:.1f}.")
         + H.bullets(report["residual_structure"] + pareto_warnings(base.summary)
                     + [bound_finding(f) for f in base.summary.at_bound])),
        ("Verdict", H.paragraph(f"verdict: {report['verdict']}. " + report["conclusion"]) + H.paragraph(significance_statement(report))),
        ("Ranking", H.table(["change", "screening gain (max log posterior)", "delta ELPD-LOO +- SE", "RMSE(DOP) after",
                             "significant (> 2 SE and > 4)"], ranking_rows(report))
         + H.bullets([f"{_name(r)}: {r['explanation']}" for r in report["ranking"]
                      if r["delta_elpd"] is not None or r.get("dominated_by")])),
        ("Signatures", H.image(H.png_file_to_data_uri(paths["signatures"]),
                               "Dots: residuals of the base fit / noise. Crosses: what each candidate changes in the "
                               "prediction, in the same units. A candidate that explains the misfit follows the dots.")),
        ("Residuals of the base fit", H.image(H.png_file_to_data_uri(paths["base"]))
         + H.image(H.png_file_to_data_uri(paths["trends"]), "The structure: residuals against each variable.")),
    ]
    if path_rungs:
        paths["path"] = out / "path.png"
        save_figure(ladder_figure(path_rungs), paths["path"])
        public = [r.to_json() for r in path_rungs]
        table = ladder_table(public)
        with atomic_path(out / "path.md") as tmp:
            tmp.write_text("\n".join(table) + "\n", encoding="utf-8")
        rows = [[i, r["model"], r.get("change") or "(start)",
                 "" if r.get("delta_elpd") is None else f"{r['delta_elpd']:+.1f} +- {r['delta_elpd_se']:.1f}",
                 fit_words(r["chi2_red"], r.get("inferred_noise", {})),
                 "structured" if r.get("structured") else "noise-like"] for i, r in enumerate(public)]
        sections.insert(1, ("The path, round by round", H.paragraph(report.get("conclusion_rounds", ""))
                            + H.table(["round", "model", "change", "delta ELPD-LOO +- SE", "fit", "residuals"], rows)
                            + H.image(H.png_file_to_data_uri(paths["path"]),
                                      "Residuals per round (top); ELPD-LOO and the error measure per round (bottom).")))
    with atomic_path(out / "report.html") as tmp:
        tmp.write_text(H.page(f"spacepol diagnose: what is missing from {report['model']}", sections), encoding="utf-8")
    return paths
