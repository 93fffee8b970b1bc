"""``results.csv``: one row per set (DESIGN.md): id, status (ok | failed | skipped), seconds, NAME_median,
NAME_q05, NAME_q95 per parameter, rhat_max, ess_min, error. Rewritten atomically after every finished
set, so an interrupted batch leaves a table of what it finished."""

from __future__ import annotations

import csv
import math

from ..infer.run_summary import RunSummary
from ..io.atomic import atomic_path

QUANTITIES = ("median", "q05", "q95")


def table_row(outcome: dict) -> dict:
    """Flat CSV fields of one job's outcome (``job.run_job``'s dict, or a skipped set's)."""
    row = {"id": outcome["id"], "status": outcome["status"], "seconds": f"{outcome['seconds']:.1f}"}
    summary = RunSummary.from_json(outcome["summary"]) if outcome.get("summary") else RunSummary(model="")
    for name, stats in summary.parameters.items():
        for q in QUANTITIES:
            row[f"{name}_{q}"] = _number(stats.get(q))
    diagnostics = summary.diagnostics
    row["rhat_max"], row["ess_min"] = _number(diagnostics.get("rhat_max")), _number(diagnostics.get("ess_min"))
    row["error"] = outcome.get("error", "")
    return row


def _number(value) -> str:
    return "" if value is None or (isinstance(value, float) and not math.isfinite(value)) else repr(float(value))


def write_results(path, rows: list[dict]) -> None:
    """``results.csv`` atomically: per set its id, status, seconds, each parameter's median and interval, R-hat, ESS
    and the error line."""
    parameters = []
    for row in rows:
        for key in row:
            name = key.rsplit("_", 1)[0]
            if key.endswith("_median") and name not in parameters:
                parameters.append(name)
    columns = ["id", "status", "seconds"] + [f"{p}_{q}" for p in parameters for q in QUANTITIES] + ["rhat_max", "ess_min", "error"]
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=columns, restval="")
        writer.writeheader()
        writer.writerows(rows)
