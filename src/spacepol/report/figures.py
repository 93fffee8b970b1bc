"""Figures.  Every function returns a Figure and accepts ``ax=`` to draw into an existing one."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure


def _axes(ax, figsize=(6.4, 4.2)):
    if ax is not None:
        return ax.figure, ax
    fig = Figure(figsize=figsize, layout="constrained")
    return fig, fig.add_subplot()


def dop_versus_theta_r(dataset, curves: dict, ax=None, title: str = "") -> Figure:
    """Measured DOP against theta_r, one colour per incidence angle, with model curves.

    ``curves`` maps a label to (geometry, dop) evaluated on a fine grid; the grid's theta_i
    values select the colour.
    """
    fig, ax = _axes(ax)
    colours = {}
    for i, ti in enumerate(np.unique(dataset.theta_i)):
        colours[ti] = f"C{i}"
        sel = dataset.theta_i == ti
        signed_r = np.where(np.cos(np.radians(dataset.dphi[sel])) < 0, dataset.theta_r[sel], -dataset.theta_r[sel])
        ax.plot(signed_r, dataset.dop[sel], "o", ms=3.5, color=colours[ti], label=f"data, theta_i = {ti:.0f} deg")
    styles = ["-", "--", ":", "-."]
    for j, (label, (geometry, dop)) in enumerate(curves.items()):
        for ti in np.unique(geometry.theta_i):
            sel = geometry.theta_i == ti
            signed_r = np.where(np.cos(np.radians(geometry.dphi[sel])) < 0, geometry.theta_r[sel], -geometry.theta_r[sel])
            order = np.argsort(signed_r)
            colour = colours.get(min(colours, key=lambda t: abs(t - ti))) if colours else "k"
            ax.plot(signed_r[order], np.asarray(dop)[sel][order], styles[j % 4], color=colour, lw=1.2,
                    label=label if ti == np.unique(geometry.theta_i)[0] else None)
    ax.set_xlabel("theta_r (deg); negative = backscatter side (dphi = 0)")
    ax.set_ylabel("degree of polarization")
    ax.set_title(title)
    ax.legend(fontsize=7, ncol=2)
    ax.grid(alpha=0.3)
    return fig
