"""The ladder: fit M, then M + E1, then M + E1 + E2, ...; show the error fall rung by rung."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ..infer.inversion import invert
from ..infer.posterior import Posterior
from ..physics.model import Model
from ..infer.inference_data import standardised_residuals


def climb(data, model: Model, additions: list[str], seed: int = 0, observables=None, max_steps: int = 8000,
          progress: bool = True) -> list[dict]:
    rungs, current = [], model
    for step in [None] + list(additions):
        if step is not None:
            current = current + step
        if progress:
            print(f"  fitting {current.name} ...", flush=True)
        post = Posterior.build(data, current, observables=observables)
        inv = invert(post, seed=seed, max_steps=max_steps, progress=False)
        fit = inv.summary["fit"]
        rungs.append({"model": current.name, "rmse_dop": fit["rmse_dop"], "chi2_red": fit["chi2_red"],
                      "elpd_loo": fit["elpd_loo"], "elpd_loo_se": fit["elpd_loo_se"],
                      "rhat_max": inv.summary["diagnostics"]["rhat_max"], "_inversion": inv})
    return rungs


def ladder_figure(rungs, fig=None) -> Figure:
    """Top: DOP residual / noise against theta_r for every rung; bottom: RMSE, chi2_red, ELPD per rung."""
    fig = fig or Figure(figsize=(3.2 * len(rungs) + 1, 6.0), layout="constrained")
    grid = fig.add_gridspec(2, len(rungs))
    for i, rung in enumerate(rungs):
        inv = rung["_inversion"]
        ax = fig.add_subplot(grid[0, i])
        obs = inv.posterior.likelihood.observables[0]
        z = standardised_residuals(inv.posterior, inv.result.flat_samples())[obs]
        data = inv.posterior.likelihood.data
        signed = np.where(np.cos(np.radians(data.dphi)) < 0, data.theta_r, -data.theta_r)
        ax.scatter(signed, z, s=8, c=data.theta_i, cmap="viridis")
        ax.axhline(0, color="k", lw=0.8)
        for level in (-2, 2):
            ax.axhline(level, color="k", lw=0.5, ls=":")
        ax.set_title(rung["model"].replace("+", "\n+"), fontsize=7)
        ax.set_xlabel("theta_r (deg)", fontsize=8)
        if i == 0:
            ax.set_ylabel(f"{obs} residual / noise")
    ax = fig.add_subplot(grid[1, :])
    x = np.arange(len(rungs))
    ax.plot(x, [r["chi2_red"] for r in rungs], "o-", label="reduced chi^2")
    ax.axhline(1, color="k", lw=0.5, ls=":")
    ax.set_yscale("log")
    ax.set_xticks(x, [r["model"].split("+")[-1] if i else r["model"] for i, r in enumerate(rungs)], fontsize=8)
    ax.set_ylabel("reduced chi^2")
    ax2 = ax.twinx()
    ax2.errorbar(x, [r["elpd_loo"] for r in rungs], yerr=[r["elpd_loo_se"] for r in rungs], fmt="s--", color="C1", label="ELPD-LOO")
    ax2.set_ylabel("ELPD-LOO", color="C1")
    ax.set_title("each rung adds one effect: the error falls towards the noise floor (chi^2 = 1)", fontsize=9)
    return fig
