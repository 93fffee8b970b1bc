"""Figures of model criticism: does a candidate effect's signature match the observed misfit?"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ..infer.inference_data import standardised_residuals
from .inversion_figures import signed_theta_r
from .panels import margin_colorbar, panel_grid, top_title


def signature_figure(base, candidates, fig=None) -> Figure:
    """Observed residuals of the base fit (dots) against each candidate's signature (crosses).

    ``base`` is the base model's Result, ``candidates`` a list of (effect name, its
    ``criticism.diagnose.signatures``). The signature of a candidate is what it changes in the prediction, in noise
    units: (posterior-median prediction of M + E) - (that of M), divided by the noise. Where the
    crosses follow the dots, the effect explains the misfit.
    """
    data, observables = base.posterior.likelihood.data, base.posterior.likelihood.observables
    x = signed_theta_r(data)
    fig, axes = panel_grid(len(observables), max(len(candidates), 1), panel_in=(3.3, 2.8), fig=fig, sharex=True,
                           margin_in=(0.85, 0.6, 0.75, 1.3))
    for j, (name, sig) in enumerate(candidates):
        for i, o in enumerate(observables):
            ax = axes[i, j]
            dots = ax.scatter(x, sig[o]["observed"], s=9, c=data.theta_i, cmap="viridis", label="observed residual")
            ax.scatter(x, sig[o]["signature"], s=14, marker="x", c="C3", lw=0.8, label=f"signature of {name}")
            ax.axhline(0, color="k", lw=0.6)
            ax.set_title(f"{name}: {o} (correlation {sig[o]['correlation']:+.2f})", fontsize=8)
            if j == 0:
                ax.set_ylabel(f"{o}: residual / noise")
            if i == len(observables) - 1:
                ax.set_xlabel("theta_r (deg), + specular side")
    axes[0, 0].legend(fontsize=7)
    if candidates:
        margin_colorbar(fig, dots, "theta_i (deg) of the observed residuals", from_right_in=1.0, bottom=0.2, height=0.6)
    top_title(fig, "Observed residuals of the base model (dots) and each candidate's signature (crosses): "
              "where they agree, the candidate explains the misfit")
    return fig


def ladder_figure(rungs, fig=None) -> Figure:
    """Top: residual / noise of the first observable against theta_r for every rung (colour: theta_i,
    with its key); bottom: ELPD-LOO per rung and the error measure that applies: reduced chi^2 when the
    file gives the noise, the inferred noise level per observable when it does not (then chi^2 is ~1
    by construction and says nothing)."""
    fig = fig or Figure(figsize=(3.2 * len(rungs) + 1.6, 6.4), layout="constrained")
    grid = fig.add_gridspec(2, len(rungs))
    scatter = None
    for i, rung in enumerate(rungs):
        inv = rung.inversion
        ax = fig.add_subplot(grid[0, i])
        obs = inv.posterior.likelihood.observables[0]
        z = standardised_residuals(inv.posterior, inv.draws.flat_samples())[obs]
        data = inv.posterior.likelihood.data
        scatter = ax.scatter(signed_theta_r(data), z, s=8, c=data.theta_i, cmap="viridis")
        ax.axhline(0, color="k", lw=0.8)
        for level in (-2, 2):
            ax.axhline(level, color="k", lw=0.5, ls=":")
        ax.set_title(f"rung {i}: " + rung["model"].replace("+", "\n+"), fontsize=7)
        ax.set_xlabel("theta_r (deg), + specular side", fontsize=8)
        if i == 0:
            ax.set_ylabel(f"{obs} residual / noise")
    if scatter is not None:
        fig.colorbar(scatter, ax=fig.axes[: len(rungs)], label="theta_i (deg)", shrink=0.8)
    ax = fig.add_subplot(grid[1, :])
    x = np.arange(len(rungs))
    labels = [r["model"] if i == 0 else (r.get("change") or "+ " + r["model"].split("+")[-1]).replace(" by ", " by\n")
              for i, r in enumerate(rungs)]
    ax.errorbar(x, [r["elpd_loo"] for r in rungs], yerr=[r["elpd_loo_se"] for r in rungs], fmt="s-", color="k",
                label="ELPD-LOO +- SE (higher is better)")
    ax.set_ylabel("ELPD-LOO (solid)")
    ax.set_xticks(x, labels, fontsize=8)
    noise = list(dict.fromkeys(k for r in rungs for k in r.get("inferred_noise", {})))
    ax2 = ax.twinx()
    if noise:
        for j, name in enumerate(noise):
            ax2.plot(x, [r["inferred_noise"].get(name, np.nan) for r in rungs], "o--", color=("C0", "C2", "C3", "C4")[j % 4],
                     label=f"inferred {name}")
        ax2.set_ylabel("inferred noise (dashed): the error left")
        what = "inferred noise"
        first, last = rungs[0]["inferred_noise"], rungs[-1]["inferred_noise"]
        change = ", ".join(f"{n} {first.get(n, np.nan):.3g} -> {last.get(n, np.nan):.3g}" for n in noise)
    else:
        ax2.plot(x, [r["chi2_red"] for r in rungs], "o--", color="C0", label="reduced chi^2 (known noise)")
        ax2.axhline(1, color="k", lw=0.5, ls=":")
        ax2.set_yscale("log")
        ax2.set_ylabel("reduced chi^2 (dashed; 1 = noise floor)")
        what = "reduced chi^2"
        change = f"chi^2_red {rungs[0]['chi2_red']:.3g} -> {rungs[-1]['chi2_red']:.3g}"
    ax2.set_yscale("log")
    handles = ax.get_legend_handles_labels()
    handles2 = ax2.get_legend_handles_labels()
    ax.legend(handles[0] + handles2[0], handles[1] + handles2[1], fontsize=7, loc="best")
    delta = rungs[-1]["elpd_loo"] - rungs[0]["elpd_loo"]
    ax.set_title(f"ELPD-LOO and {what} per rung: ELPD {rungs[0]['elpd_loo']:.1f} -> {rungs[-1]['elpd_loo']:.1f} "
                 f"({delta:+.1f}); {change}", fontsize=9)
    return fig


def residual_trends_figure(structure, fig=None) -> Figure:
    """Standardised residuals against theta_i, theta_r, dphi, phase angle and the DOP level (one row per
    observable), each panel with its Spearman rank correlation; a red title marks p < 0.01."""
    variables = [v for v in ("theta_i", "theta_r", "dphi", "phase_deg", "dop_level") if np.ptp(structure.variables[v]) > 0]
    fig, axes = panel_grid(len(structure.observables), len(variables), panel_in=(2.6, 2.4), gap_in=(0.35, 0.4),
                           margin_in=(0.75, 0.55, 0.45, 0.2), fig=fig, sharex="col", sharey="row")
    for i, o in enumerate(structure.observables):
        z = structure.residuals[o]
        for j, var in enumerate(variables):
            ax = axes[i, j]
            ax.scatter(structure.variables[var], z, s=6, alpha=0.7)
            ax.axhline(0, color="k", lw=0.6)
            for level in (-2, 2):
                ax.axhline(level, color="k", lw=0.4, ls=":")
            t = structure.trends[o].get(var)  # none for a constant residual
            if t is not None:
                ax.set_title(f"rho {t['rho']:+.2f}, p {t['p']:.1g}", fontsize=7, color="C3" if t["p"] < 0.01 else "k")
            if i == len(structure.observables) - 1:
                ax.set_xlabel(var.replace("_deg", " (deg)").replace("_", " "), fontsize=8)
            if j == 0:
                ax.set_ylabel(f"{o} residual / noise", fontsize=8)
    top_title(fig, "Residual trends: a physical effect shows as a trend, noise does not")
    return fig


def validation_figure(rows: list[dict], swap_rows: list[dict]) -> Figure:
    """The validation suite in one picture: detection against effect size (additions to the right base
    model) and, where swap cases ran, reduced chi^2 along each diagnose --rounds path from paper."""
    from ..validation.hidden_effects import detection_figure
    from ..validation.swap_suite import swap_figure

    panels = int(bool(rows)) + int(bool(swap_rows))
    fig = Figure(figsize=(7.0 * max(panels, 1), 4.2), layout="constrained")
    axes = fig.subplots(1, max(panels, 1), squeeze=False)[0]
    if rows:
        detection_figure(rows, ax=axes[0])
    if swap_rows:
        swap_figure(swap_rows, ax=axes[-1])
    return fig
