"""Files of ``invert-mcmc ladder``: ladder.json (DESIGN's fields), ladder.md (the table), ladder.png."""

from __future__ import annotations

from pathlib import Path

from ..io.atomic import atomic_path, save_figure, write_json
from .criticism_figures import ladder_figure


def ladder_table(public: list[dict]) -> list[str]:
    lines = ["| rung | model | RMSE(DOP) | chi2_red | ELPD-LOO | R-hat max |", "|---|---|---|---|---|---|"]
    for i, r in enumerate(public):
        rmse = "n/a" if r["rmse_dop"] is None else f"{r['rmse_dop']:.4f}"
        lines.append(f"| {i} | {r['model']} | {rmse} | {r['chi2_red']:.3f} | {r['elpd_loo']:.1f} +- {r['elpd_loo_se']:.1f} | {r['rhat_max']:.3f} |")
    return lines


def write_ladder_report(rungs: list[dict], out: Path, json_path=None) -> list[str]:
    """Write the figure, JSON and table; returns the table's lines."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    save_figure(ladder_figure(rungs), out / "ladder.png")
    public = [{k: v for k, v in r.items() if not k.startswith("_")} for r in rungs]
    write_json(json_path or out / "ladder.json", {"rungs": public})
    lines = ladder_table(public)
    with atomic_path(out / "ladder.md") as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return lines
