"""Figures of the sky: DOP/AoP maps in three projections, the projections' distortion, contrast histograms."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Ellipse

from ..skylight.projections import PROJECTIONS


def _grid(proj, n=241):
    """A square grid over the projected hemisphere disc: (x, y, zenith, azimuth, inside)."""
    r0 = proj.horizon_radius()
    x, y = np.meshgrid(np.linspace(-r0, r0, n), np.linspace(-r0, r0, n))
    zen, az = proj.inverse(x, y)
    inside = np.hypot(x, y) <= r0
    return x, y, zen, az, inside


def _frame(ax, proj, sun=None, label=True):
    r0 = proj.horizon_radius()
    ax.add_patch(Circle((0, 0), r0, fill=False, lw=0.8))
    for zen in (30, 60):
        ax.add_patch(Circle((0, 0), float(proj.radius(np.radians(zen))), fill=False, lw=0.4, ls=":"))
    if label:
        for text, (x, y) in {"N": (0, 1.08), "E": (1.08, 0), "S": (0, -1.12), "W": (-1.12, 0)}.items():
            ax.text(x * r0, y * r0, text, ha="center", va="center", fontsize=7)
    if sun is not None and sun[0] <= 90:
        sx, sy = proj.forward(sun[0], sun[1])
        ax.plot(sx, sy, "o", ms=7, mfc="gold", mec="k")
    ax.set_xlim(-1.2 * r0, 1.2 * r0)
    ax.set_ylim(-1.2 * r0, 1.2 * r0)
    ax.set_aspect("equal")
    ax.set_axis_off()


def sky_maps_figure(sky, sun, points=None, fig=None) -> Figure:
    """DOP (top) and AoP (bottom) over the hemisphere in the stereographic, orthographic and
    equal-area projections; dotted circles at 30 and 60 deg zenith angle; the sun in gold;
    ``points``: {label: (zenith, azimuth)} marked (e.g. neutral points, targets)."""
    fig = fig or Figure(figsize=(11, 7.2), layout="constrained")
    axes = fig.subplots(2, len(PROJECTIONS))
    for j, proj in enumerate(PROJECTIONS.values()):
        x, y, zen, az, inside = _grid(proj)
        dop = np.where(inside, sky.dop(zen, az, sun), np.nan)
        aop = np.where(inside, sky.aop(zen, az, sun), np.nan)
        m0 = axes[0, j].pcolormesh(x, y, dop, vmin=0, vmax=1, cmap="viridis", shading="auto")
        m1 = axes[1, j].pcolormesh(x, y, aop, vmin=-90, vmax=90, cmap="twilight_shifted", shading="auto")
        for ax in axes[:, j]:
            _frame(ax, proj, sun)
            for label, (pz, pa) in (points or {}).items():
                if pz <= 90:
                    px, py = proj.forward(pz, pa)
                    ax.plot(px, py, "w^" if "target" not in label else "rs", ms=5, mec="k")
                    ax.annotate(label, (px, py), fontsize=6, xytext=(3, 3), textcoords="offset points", color="w")
        axes[0, j].set_title(proj.label, fontsize=8)
    fig.colorbar(m0, ax=axes[0, :], shrink=0.8, label="degree of polarization")
    fig.colorbar(m1, ax=axes[1, :], shrink=0.8, label="AoP from the local meridian (deg)")
    fig.suptitle(f"{sky.name} sky, P_max {sky.p_max:g}; sun at zenith {sun[0]:.2f} deg, azimuth {sun[1]:.2f} deg", fontsize=9)
    return fig


def projection_distortion_figure(fig=None) -> Figure:
    """Top: Tissot ellipses (the image of a small circle on the sky) at zenith 0-80 deg in each
    projection. Bottom: angular distortion and areal scale against zenith angle."""
    fig = fig or Figure(figsize=(11, 7.5), layout="constrained")
    grid = fig.add_gridspec(2, len(PROJECTIONS))
    zen = np.linspace(0, 89.5, 300)
    for j, proj in enumerate(PROJECTIONS.values()):
        ax = fig.add_subplot(grid[0, j])
        _frame(ax, proj)
        size = np.radians(7.0)  # the image of a 7 deg circle on the sky, in map units
        for z in (0, 20, 40, 60, 80):
            for a in range(0, 360, 45 if z else 360):
                t = proj.tissot(z)
                x, y = proj.forward(z, a)
                # h along the meridian (radial), k along the parallel
                ax.add_patch(Ellipse((x, y), 2 * size * float(t["k"]), 2 * size * float(t["h"]), angle=-a,
                                     fc="C3", alpha=0.5, ec="k", lw=0.3))
        t60 = proj.tissot(60)
        ax.set_title(f"{proj.label}\nat 60 deg: angular distortion {float(t60['angular_distortion_deg']):.1f} deg, "
                     f"areal scale {float(t60['areal_scale']):.2f}", fontsize=7)
    ax1, ax2 = fig.add_subplot(grid[1, : len(PROJECTIONS) // 2 + 1]), fig.add_subplot(grid[1, len(PROJECTIONS) // 2 + 1:])
    for proj in PROJECTIONS.values():
        t = proj.tissot(zen)
        ax1.plot(zen, t["angular_distortion_deg"], label=proj.name)
        ax2.plot(zen, t["areal_scale"], label=proj.name)
    ax1.set_xlabel("zenith angle (deg)")
    ax1.set_ylabel("max angular distortion (deg)")
    ax2.set_xlabel("zenith angle (deg)")
    ax2.set_ylabel("areal scale (map area / sky solid angle)")
    ax2.set_yscale("log")
    for ax in (ax1, ax2):
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
    fig.suptitle("The hemisphere in three projections: stereographic keeps shapes (conformal), equal-area keeps "
                 "areas, orthographic keeps neither near the horizon", fontsize=9)
    return fig


def contrast_histograms(draws: dict, fig=None) -> Figure:
    """One row per case: histograms of target DOP, sky DOP, limiting magnitude, intensity and
    polarization contrast over the Monte-Carlo draws, with the 5/50/95 % quantiles."""
    quantities = ["target_dop", "sky_dop", "limiting_magnitude", "intensity_contrast", "polarization_contrast"]
    fig = fig or Figure(figsize=(14, 2.6 * len(draws) + 0.6), layout="constrained")
    axes = fig.subplots(len(draws), len(quantities), squeeze=False)
    for i, (case, values) in enumerate(draws.items()):
        for j, q in enumerate(quantities):
            ax = axes[i, j]
            v = np.asarray(values[q], float)
            v = v[np.isfinite(v)]
            if v.size and np.ptp(v) <= 1e-9 * max(1.0, abs(float(np.median(v)))):
                # a single spike would look like a plotting error: say why there is no spread
                ax.axvline(v[0], color="C0", lw=3)
                ax.text(0.5, 0.5, f"every draw gives {v[0]:.4g}:\nno input uncertainty\nreaches this quantity",
                        transform=ax.transAxes, ha="center", va="center", fontsize=7,
                        bbox={"facecolor": "white", "alpha": 0.8, "lw": 0})
            elif v.size:
                ax.hist(v, bins=60, color="C0", alpha=0.8)
                for p in np.percentile(v, [5, 50, 95]):
                    ax.axvline(p, color="k", lw=0.8, ls="--")
            ax.set_yticks([])
            if i == 0:
                ax.set_title(q.replace("_", " "), fontsize=8)
            if j == 0:
                ax.set_ylabel(case, fontsize=7)
    fig.suptitle("Table 3 as distributions over posterior, geometry and sky draws (dashed: 5, 50, 95 %)", fontsize=9)
    return fig
