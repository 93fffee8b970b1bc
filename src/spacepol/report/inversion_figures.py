"""Figures of an inversion: corner plot, data with predictive bands, residuals."""

from __future__ import annotations

import corner
import numpy as np
from matplotlib.figure import Figure

from ..infer.inference_data import predictive_means
from .panels import margin_colorbar, panel_grid, top_title


def corner_figure(result, truths: dict | None = None, fig=None) -> Figure:
    """Corner plot with 5/50/95 % quantiles; three ticks per axis so the labels do not collide."""
    flat = result.flat_samples()
    size = 2.2 * len(result.names) + 1.2
    fig = fig or Figure(figsize=(size, size))
    truth_values = None
    if truths:
        truth_values = [truths.get(n) for n in result.names]
    corner.corner(flat, labels=result.names, quantiles=[0.05, 0.5, 0.95], show_titles=True,
                  title_fmt=".3g", truths=truth_values, truth_color="C3", fig=fig, max_n_ticks=3,
                  labelpad=0.12, title_kwargs={"fontsize": 9}, label_kwargs={"fontsize": 10})
    for ax in fig.axes:
        ax.tick_params(labelsize=7)
    fig.suptitle("Posterior: marginals (5, 50, 95 % lines) and pairwise densities" +
                 ("; truths in red" if truth_values else ""), fontsize=10, y=1.0)
    return fig


def _panels(data):
    """One panel per incidence angle; x = theta_r signed by side (negative = dphi != 180)."""
    keys = np.round(data.theta_i, 3)
    return [(ti, np.flatnonzero(keys == ti)) for ti in np.unique(keys)]


def signed_theta_r(data, idx=slice(None)):
    """theta_r with a sign: + on the specular side (|dphi| > 90 deg), - on the source side."""
    forward = np.cos(np.radians(data.dphi[idx])) < 0
    return np.where(forward, data.theta_r[idx], -data.theta_r[idx])


def _in_plane(data, idx):
    return np.abs(np.sin(np.radians(data.dphi[idx]))) < 1e-6


def fit_figure(posterior, result, observables=None, max_draws: int = 2000, rng=None, fig=None,
               max_panels: int = 8, max_axes: int = 48) -> Figure:
    """Data with the posterior-median prediction and its 90 % band against theta_r: one row per
    fitted observable, one column per incidence angle (at most ``max_panels``, evenly chosen, and fewer
    where the rows times the columns would pass ``max_axes``: a full Mueller matrix keeps 3-4 angles).
    In-plane sweeps are drawn as curves; out-of-plane points (other azimuths at the same theta_r)
    as separate bars, since joining them in theta_r order would draw a sawtooth."""
    lik = posterior.likelihood
    data, observed = lik.data, lik.observed()
    observables = list(observables or lik.observables)
    flat = result.flat_samples()
    rng = rng or np.random.default_rng(0)
    if len(flat) > max_draws:
        flat = flat[rng.choice(len(flat), max_draws, replace=False)]
    means = predictive_means(posterior, flat)
    panels = _panels(data)
    keep = min(max_panels, max(3, max_axes // len(observables)))
    if len(panels) > keep:
        panels = [panels[i] for i in np.unique(np.linspace(0, len(panels) - 1, keep).round().astype(int))]
    fig, axes = panel_grid(len(observables), len(panels), fig=fig, sharex="col", margin_in=(0.75, 0.6, 0.7, 0.2))
    for row, observable in enumerate(observables):
        lo, med, hi = np.percentile(means[observable], [5, 50, 95], axis=0)
        y = observed[observable]
        err = None if lik.inferred(observable) else lik.scale(observable)
        for ax, (ti, idx) in zip(axes[row], panels):
            x = signed_theta_r(data, idx)
            plane = _in_plane(data, idx)
            if plane.any():
                order = np.argsort(x[plane])
                xi = x[plane][order]
                ax.fill_between(xi, lo[idx][plane][order], hi[idx][plane][order], color="C0", alpha=0.3, lw=0,
                                label="90 % band (in plane)")
                ax.plot(xi, med[idx][plane][order], "-", color="C0", lw=1.2, label="posterior median")
            off = ~plane
            if off.any():
                ax.vlines(x[off], lo[idx][off], hi[idx][off], color="C1", lw=2, alpha=0.5, label="90 % band (out of plane)")
                ax.plot(x[off], med[idx][off], "_", color="C1", ms=6)
            ax.errorbar(x, y[idx], yerr=None if err is None else err[idx], fmt="o", ms=2.5, color="k", lw=0.8, label="data")
            owner = lik.observable_of(observable)
            if owner.relative_noise and np.all(y[idx] > 0):  # a multiplicative noise: a log axis
                ax.set_yscale("log")
            if row == 0:
                ax.set_title(f"theta_i = {ti:g} deg", fontsize=9)
            if row == len(observables) - 1:
                ax.set_xlabel("theta_r (deg; < 0: source side)", fontsize=8)
            ax.set_ylabel(owner.axis_label(observable), fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=6)
    top_title(fig, "Measured data (black) against the model: posterior median and 90 % band of the noise-free prediction")
    return fig


def residual_figure(posterior, result, fig=None) -> Figure:
    """Standardised residuals (data - median prediction) / noise against theta_r, per observable."""
    from ..infer.inference_data import standardised_residuals

    data = posterior.likelihood.data
    residuals = standardised_residuals(posterior, result.flat_samples())
    observables = posterior.likelihood.observables
    fig, axes = panel_grid(len(observables), 1, panel_in=(7.0, 2.4 if len(observables) > 4 else 2.8), fig=fig, sharex=True,
                           margin_in=(0.75, 0.6, 0.45, 0.2))
    axes = axes.ravel()
    for ax, o in zip(axes, observables):
        z = residuals[o]
        for i, (ti, idx) in enumerate(_panels(data)):
            ax.plot(signed_theta_r(data, idx), z[idx], "o", ms=3, color=f"C{i % 10}", label=f"theta_i = {ti:g}")
        ax.axhline(0, color="k", lw=0.8)
        for level in (-2, 2):
            ax.axhline(level, color="k", lw=0.5, ls=":")
        ax.set_ylabel(f"{o} residual / noise")
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("theta_r (deg; < 0: source side)")
    axes[0].legend(fontsize=7, ncol=4)
    axes[0].set_title("Standardised residuals (data - posterior-median prediction) / noise; noise alone stays within +-2",
                      fontsize=9)
    return fig


def mueller_residual_figure(posterior, result, fig=None) -> Figure:
    """Standardised residuals of a full-Mueller fit laid out as the matrix: panel (i, j) holds m_ij's
    residuals against signed theta_r (colour: theta_i), panel (1, 1) the BRDF's when it was fitted. A
    misfit confined to a row (the analyser side) or a column (the generator side) points to an instrument
    effect; one spread over the whole matrix to the sample's physics."""
    from ..infer.inference_data import standardised_residuals

    lik = posterior.likelihood
    data, residuals = lik.data, standardised_residuals(posterior, result.flat_samples())
    x = signed_theta_r(data)
    fig, axes = panel_grid(4, 4, panel_in=(2.7, 2.1), gap_in=(0.45, 0.45), margin_in=(0.5, 0.55, 0.45, 1.2),
                           fig=fig, sharex=True)
    dots = None
    for i in range(4):
        for j in range(4):
            ax = axes[i, j]
            name = "brdf" if i == j == 0 else f"m{i + 1}{j + 1}"
            if name not in residuals:
                ax.set_axis_off()
                continue
            z = residuals[name]
            dots = ax.scatter(x, z, s=4, c=data.theta_i, cmap="viridis", alpha=0.7)
            for level in (-2, 2):
                ax.axhline(level, color="k", lw=0.4, ls=":")
            ax.axhline(0, color="k", lw=0.6)
            rms = float(np.sqrt(np.mean(z**2)))
            ax.set_title(f"{name}: RMS {rms:.2f}", fontsize=8, color="C3" if rms > 1.5 else "k")
            ax.tick_params(labelsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("theta_r (deg; < 0: source side)", fontsize=7)
    if dots is not None:
        margin_colorbar(fig, dots, "theta_i (deg)", from_right_in=0.95, bottom=0.25, height=0.5)
    top_title(fig, "Standardised residuals per Mueller element (noise alone: RMS ~ 1, within +-2; red title: RMS > 1.5)")
    return fig
