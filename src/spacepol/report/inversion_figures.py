"""Figures of an inversion: corner plot, data with predictive bands, residuals."""

from __future__ import annotations

import corner
import numpy as np
from matplotlib.figure import Figure

from ..infer.inference_data import predictive_means


def corner_figure(result, truths: dict | None = None, fig=None) -> Figure:
    flat = result.flat_samples()
    fig = fig or Figure(figsize=(2.0 * len(result.names) + 1, 2.0 * len(result.names) + 1))
    truth_values = None
    if truths:
        truth_values = [truths.get(n) for n in result.names]
    corner.corner(flat, labels=result.names, quantiles=[0.05, 0.5, 0.95], show_titles=True,
                  title_fmt=".3g", truths=truth_values, truth_color="C3", fig=fig)
    return fig


def _panels(data):
    """One panel per incidence angle; x = theta_r signed by side (negative = dphi != 180)."""
    keys = np.round(data.theta_i, 3)
    return [(ti, np.flatnonzero(keys == ti)) for ti in np.unique(keys)]


def signed_theta_r(data, idx=slice(None)):
    """theta_r with a sign: + on the specular side (|dphi| > 90 deg), - on the source side."""
    forward = np.cos(np.radians(data.dphi[idx])) < 0
    return np.where(forward, data.theta_r[idx], -data.theta_r[idx])


def fit_figure(posterior, result, observable: str = "dop", max_draws: int = 2000, rng=None, fig=None) -> Figure:
    """Data, posterior-median prediction and its 90 % band against theta_r, one panel per theta_i."""
    data = posterior.likelihood.data
    flat = result.flat_samples()
    rng = rng or np.random.default_rng(0)
    if len(flat) > max_draws:
        flat = flat[rng.choice(len(flat), max_draws, replace=False)]
    means = predictive_means(posterior, flat)[observable]
    lo, med, hi = np.percentile(means, [5, 50, 95], axis=0)
    panels = _panels(data)
    cols = min(4, len(panels))
    rows = int(np.ceil(len(panels) / cols))
    fig = fig or Figure(figsize=(3.6 * cols, 2.9 * rows), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    y = getattr(data, observable)
    err = getattr(data, f"{observable}_err")
    for ax, (ti, idx) in zip(axes, panels):
        x = signed_theta_r(data, idx)
        order = np.argsort(x)
        ax.fill_between(x[order], lo[idx][order], hi[idx][order], color="C0", alpha=0.3, lw=0, label="90 % band")
        ax.plot(x[order], med[idx][order], "-", color="C0", lw=1.2, label="posterior median")
        ax.errorbar(x, y[idx], yerr=None if err is None else err[idx], fmt="o", ms=3, color="k", lw=0.8, label="data")
        ax.set_title(f"theta_i = {ti:g} deg", fontsize=9)
        ax.set_xlabel("theta_r (deg, < 0: dphi != 180)", fontsize=8)
        ax.set_ylabel({"dop": "DOP", "brdf": "BRDF (sr^-1)", "q": "q = S1/S0", "u": "u = S2/S0"}[observable], fontsize=8)
        ax.grid(alpha=0.3)
    for ax in axes[len(panels):]:
        ax.set_visible(False)
    axes[0].legend(fontsize=7)
    return fig


def residual_figure(posterior, result, fig=None) -> Figure:
    """Standardised residuals (data - median prediction) / noise against theta_r, per observable."""
    from ..infer.inference_data import standardised_residuals

    data = posterior.likelihood.data
    residuals = standardised_residuals(posterior, result.flat_samples())
    observables = posterior.likelihood.observables
    fig = fig or Figure(figsize=(7.0, 2.8 * len(observables)), layout="constrained")
    axes = fig.subplots(len(observables), 1, squeeze=False).ravel()
    for ax, o in zip(axes, observables):
        z = residuals[o]
        for i, (ti, idx) in enumerate(_panels(data)):
            ax.plot(signed_theta_r(data, idx), z[idx], "o", ms=3, color=f"C{i % 10}", label=f"theta_i = {ti:g}")
        ax.axhline(0, color="k", lw=0.8)
        for level in (-2, 2):
            ax.axhline(level, color="k", lw=0.5, ls=":")
        ax.set_ylabel(f"{o} residual / noise")
        ax.set_xlabel("theta_r (deg, < 0: dphi != 180)")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7, ncol=4)
    return fig
