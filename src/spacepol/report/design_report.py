"""Files of ``invert-mcmc design``: design.json, design.md (the findings and the picks) and design.png (how
much one measurement of each kind shrinks the ridge, over theta_i and theta_r in the specular plane)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ..io.atomic import atomic_path, save_figure, write_json
from ..observables import get as get_observable


def shrink_map_figure(maps: dict, fig=None) -> Figure:
    """One panel per observable: shrink factor of the ridge's sd by a single measurement at (theta_i, theta_r)."""
    fig = fig or Figure(figsize=(4.2 * len(maps), 3.8), layout="constrained")
    axes = fig.subplots(1, len(maps), squeeze=False)[0]
    top = max(1.1, max(float(np.nanmax(grid)) for _, grid in maps.values()))  # one scale: a flat 1 reads as "no help"
    for ax, (name, (angles, grid)) in zip(axes, maps.items()):
        image = ax.pcolormesh(angles, angles, grid.T, shading="nearest", cmap="viridis", vmin=1.0, vmax=top)
        ax.set_xlabel("theta_i (deg)")
        ax.set_ylabel("theta_r (deg), dphi = 180")
        ax.set_title(f"{name}: ridge sd / sd with it", fontsize=9)
        fig.colorbar(image, ax=ax)
    return fig


def write_design_report(report: dict, out: Path, source: str) -> list[str]:
    """design.png, design.json and design.md in ``out``; returns design.md's lines."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    save_figure(shrink_map_figure(shrink_maps(report)), out / "design.png")
    write_json(out / "design.json", report)
    lines = design_lines(report, source)
    with atomic_path(out / "design.md") as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return lines


def design_lines(report: dict, source: str) -> list[str]:
    """design.md's lines: the findings, the picks as a table and the ridge."""
    lines = [f"# Experiment design for {source}", "", *report["findings"], "",
             "| pick | measurement | noise | ridge sd after (prior units) | shrink |", "|---|---|---|---|---|"]
    for i, p in enumerate(report["picks"], 1):
        noise = f"{100 * p['noise']:.0f} %" if get_observable(p["observable"]).relative_noise else f"{p['noise']:g}"
        lines.append(f"| {i} | {p['measurement']} | {noise} | {p['sd_after']:.3g} | {p['shrink']:.1f}x |")
    lines += ["", f"Ridge: {', '.join(report['ridge']['parameters'])}, direction "
              + ", ".join(f"{n} {c:+.2f}" for n, c in report["ridge"]["direction"].items() if abs(c) > 1e-3)
              + f" (in prior-sd units); sd before {report['ridge']['sd_relative_to_prior']:.3f} of the prior's.",
              "The factors are a linear (Fisher) prediction at the point; add the measurements and invert again to see the real one."]
    return lines


def shrink_maps(report: dict, dphi: float = 180.0) -> dict:
    """{observable: (angles, (n, n) shrink factors)} of single measurements in the plane ``dphi``."""
    maps = {}
    for name, rows in report["single"].items():
        rows = np.array([r for r in rows if r[2] == dphi])
        angles = np.unique(rows[:, 0])
        grid = np.full((angles.size, angles.size), np.nan)
        for ti, tr, _, shrink in rows:
            grid[np.searchsorted(angles, ti), np.searchsorted(angles, tr)] = shrink
        maps[name] = (angles, grid)
    return maps
