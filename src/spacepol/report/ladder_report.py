"""Files of ``invert-mcmc ladder``: ladder.json (DESIGN's fields), ladder.md (the table), ladder.png."""

from __future__ import annotations

from pathlib import Path

from ..infer.identifiability import bound_finding
from ..io.atomic import atomic_path, save_figure, write_json
from .criticism_figures import ladder_figure


def _posterior_check(rung: dict) -> str:
    """R-hat of an emcee fit, or the importance weights' Pareto k of a Laplace fit (``inversion.invert_laplace``)."""
    if rung.get("rhat_max") is not None:
        return f"R-hat {rung['rhat_max']:.3f}"
    if rung.get("pareto_k") is not None:
        return f"Laplace-IS, Pareto k {rung['pareto_k']:.2f}"
    return "n/a"


def ladder_table(public: list[dict]) -> list[str]:
    """The ladder as a Markdown table: model, fit figures, ELPD-LOO and its change, how each posterior was obtained."""
    noise = list(dict.fromkeys(k for r in public for k in r.get("inferred_noise", {})))
    head = ("| rung | model | RMSE(DOP) | chi2_red | ELPD-LOO | ln Z |" + "".join(f" {n} (inferred) |" for n in noise)
            + " posterior check |")
    lines = [head, "|" + "---|" * (7 + len(noise))]
    for i, r in enumerate(public):
        rmse = "n/a" if r["rmse_dop"] is None else f"{r['rmse_dop']:.4f}"
        cells = "".join(f" {r['inferred_noise'].get(n, float('nan')):.4g} |" for n in noise)
        log_z = "n/a" if r.get("log_evidence") is None else f"{r['log_evidence']:.1f} +- {r['log_evidence_error']:.2f}"
        lines.append(f"| {i} | {r['model']} | {rmse} | {r['chi2_red']:.3f} | {r['elpd_loo']:.1f} +- {r['elpd_loo_se']:.1f} |"
                     f" {log_z} |{cells} {_posterior_check(r)} |")
    flags = [f"rung {i}: {bound_finding(f)}" for i, r in enumerate(public) for f in r.get("at_bound", [])]
    if flags:
        lines.append("")
        lines.extend(flags)
    if noise:
        lines.append("")
        lines.append("The noise is inferred (the file gives no errors), so reduced chi^2 is ~1 at every rung by construction; "
                     "the error that falls is the inferred noise level, and ELPD-LOO (higher is better) ranks the rungs.")
    if any(r.get("log_evidence") is not None for r in public):
        lines.append("")
        lines.append("ln Z: the log evidence (Laplace-IS where its weights are trusted, or the engine's own); a difference "
                     "of more than 3 between rungs is strong evidence (Kass & Raftery 1995). n/a: not trusted there.")
    return lines


def write_ladder_report(rungs: list[dict], out: Path, json_path=None) -> list[str]:
    """Write the figure, JSON and table; returns the table's lines."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    save_figure(ladder_figure(rungs), out / "ladder.png")
    public = [r.to_json() for r in rungs]
    write_json(json_path or out / "ladder.json", {"rungs": public})
    lines = ladder_table(public)
    with atomic_path(out / "ladder.md") as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return lines
