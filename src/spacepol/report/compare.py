"""``invert-mcmc compare``: every optimizer, several seeds, beside the posterior.

All methods search the same prior cube and are scored by the same objective, the paper's
eq 25 (relative squared DOP error) at the point they return; emcee's point is its MAP.
A run "succeeds" when its objective is within ``rtol`` of the best objective any run reached.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ..infer.engine_registry import OPTIMIZERS, SAMPLER, check_method, engines, optimize
from ..infer.objective import PaperObjective
from ..infer.prior_set import PriorSet
from ..io.atomic import atomic_path, save_figure, write_json

DEFAULT_METHODS = OPTIMIZERS + ["emcee"]


def _model_priors(posterior):
    model = posterior.likelihood.model
    names = {p.name for p in model.parameters}
    return PriorSet(model.parameters, {n: pr for n, pr in posterior.priors.priors.items() if n in names})


def run_comparison(posterior, data, out: Path, methods=None, seeds: int = 3, base_seed: int = 0, rtol: float = 0.01,
                   progress: bool = True) -> dict:
    """Every engine in ``methods`` from ``seeds`` starts on the same posterior: best objective against evaluations and
    the spread of the optima; figures, JSON and report.html in ``out``; returns the JSON record."""
    methods = methods or DEFAULT_METHODS
    for m in methods:
        check_method(m)
    if len(set(methods)) != len(methods):
        from ..errors import UnknownNameError

        raise UnknownNameError(f"--methods {' '.join(methods)}: a method is named twice")
    model = posterior.likelihood.model
    objective = PaperObjective(data, model, _model_priors(posterior))
    runs = []
    inv = None
    for method in methods:
        engine = engines.get(method)
        for k in range(seeds if engine.kind != SAMPLER else 1):
            seed = base_seed + k
            if progress:
                print(f"  {method} seed {seed} ...", flush=True)
            if engine.kind == SAMPLER:
                inv = engine.result(posterior, seed=seed)
                res = inv.draws
                point = np.array([[res.best.get(n, posterior.priors.fixed.get(n)) for n in objective.names]])
                value = float(objective(point)[0])
                runs.append({"method": method, "seed": seed, "objective": value, "best": {n: float(point[0, j]) for j, n in enumerate(objective.names)},
                             "n_evaluations": res.n_evaluations + res.info.get("init_evaluations", 0),
                             "seconds": res.seconds, "history": None})
            else:
                res = optimize(method, objective, np.random.default_rng(seed), model.name, seed=seed)
                runs.append({"method": method, "seed": seed, "objective": res.objective, "best": res.best,
                             "n_evaluations": res.n_evaluations, "seconds": res.seconds, "history": res.history})
    best_known = min(r["objective"] for r in runs)
    for r in runs:
        r["success"] = bool(r["objective"] <= best_known * (1 + rtol) + 1e-12)
    interval = {}
    if inv is not None:
        interval = {n: [q["q05"], q["q95"]] for n, q in inv.summary.parameters.items()}
    table = _table(runs, methods, objective.names)
    report = {"objective": objective.name, "best_known": best_known, "success_rtol": rtol,
              "posterior_90": interval, "methods": table,
              "runs": [{k: v for k, v in r.items() if k != "history"} for r in runs]}
    out.mkdir(parents=True, exist_ok=True)
    write_json(out / "optimizers.json", report)
    save_figure(convergence_figure(runs, best_known), out / "optimizers.png")
    with atomic_path(out / "optimizers.md") as tmp:
        tmp.write_text(_markdown(report, objective.names), encoding="utf-8")
    print(f"wrote {out}/optimizers.json, optimizers.png, optimizers.md")
    return report


def _table(runs, methods, names):
    rows = []
    for method in methods:
        mine = [r for r in runs if r["method"] == method]
        best = min(mine, key=lambda r: r["objective"])
        rows.append({
            "method": method, "runs": len(mine), "best_objective": best["objective"],
            "median_objective": float(np.median([r["objective"] for r in mine])),
            "success_rate": float(np.mean([r["success"] for r in mine])),
            "median_evaluations": float(np.median([r["n_evaluations"] for r in mine])),
            "median_seconds": float(np.median([r["seconds"] for r in mine])),
            "best": best["best"],
        })
    return rows


def _markdown(report, names) -> str:
    post = report["posterior_90"]
    head = "| method | runs | best eq-25 objective | success | median evals | median s | " + " | ".join(names) + " |"
    sep = "|" + "---|" * (6 + len(names))
    lines = [f"Objective: {report['objective']} (lower is better); best known {report['best_known']:.6g}; "
             f"success = within {100 * report['success_rtol']:.0f} % of it.", "", head, sep]
    for row in report["methods"]:
        values = " | ".join(f"{row['best'].get(n, float('nan')):.4g}" for n in names)
        lines.append(f"| {row['method']} | {row['runs']} | {row['best_objective']:.6g} | {100 * row['success_rate']:.0f} % | "
                     f"{row['median_evaluations']:.0f} | {row['median_seconds']:.2f} | {values} |")
    if post:
        lines.append("| posterior 90 % | | | | | | " + " | ".join(
            f"[{post[n][0]:.3g}, {post[n][1]:.3g}]" if n in post else "" for n in names) + " |")
    lines += ["", "Parameters that the posterior leaves wide are not determined by the data: different "
              "optimizers then return different values with the same objective, and none of them is 'the' answer."]
    return "\n".join(lines) + "\n"


def convergence_figure(runs, best_known, fig=None) -> Figure:
    """Best objective against evaluations for each engine and seed; returns the Figure."""
    fig = fig or Figure(figsize=(7, 4.5), layout="constrained")
    ax = fig.add_subplot()
    methods = sorted({r["method"] for r in runs}, key=lambda m: [r["method"] for r in runs].index(m))
    for i, method in enumerate(methods):
        for j, r in enumerate(x for x in runs if x["method"] == method):
            if r["history"] is None:
                ax.plot(r["n_evaluations"], r["objective"] - best_known + 1e-12, "*", ms=10, color=f"C{i}",
                        label=method if j == 0 else None)
                continue
            h = r["history"]
            ax.plot(h[:, 0], h[:, 1] - best_known + 1e-12, color=f"C{i}", lw=1, alpha=0.8, label=method if j == 0 else None)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("objective evaluations")
    ax.set_ylabel("best objective - best known (+1e-12)")
    ax.set_title("Optimizer convergence on eq 25 (same prior cube)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, ncol=2)
    return fig
