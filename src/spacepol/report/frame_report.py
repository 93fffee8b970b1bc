"""Files of ``invert-mcmc frame``: a raw micro-polarizer frame's Stokes, DoLP and AoP maps as ``frame.png``,
``stokes.npz`` (the arrays) and ``frame.json`` (what was read and the maps' statistics)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ..io.atomic import atomic_path, save_figure, write_json


def stokes_maps_figure(maps, fig=None) -> Figure:
    """S0, DoLP and AoP of a frame (``camera.mosaic.StokesMaps``); the AoP in a cyclic colour map."""
    fig = fig or Figure(figsize=(12.0, 3.8), layout="constrained")
    axes = fig.subplots(1, 3)
    for ax, (image, title, cmap, limits) in zip(axes, (
            (maps.stokes[0], "S0 (counts)", "gray", (None, None)), (maps.dolp, "DoLP", "viridis", (0.0, 1.0)),
            (maps.aop_deg, "AoP (deg from the sensor's x axis)", "twilight", (0.0, 180.0)))):
        shown = ax.imshow(image, cmap=cmap, vmin=limits[0], vmax=limits[1])
        ax.set_title(title, fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
        fig.colorbar(shown, ax=ax, shrink=0.8)
    fig.suptitle(f"{Path(maps.source).name or 'raw frame'}: {maps.method} demosaicking", fontsize=10)
    return fig


def write_frame_report(maps, out: Path) -> dict:
    """frame.png, stokes.npz and frame.json in ``out``; returns frame.json's content."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    content = maps.to_json()
    save_figure(stokes_maps_figure(maps), out / "frame.png")
    with atomic_path(out / "stokes.npz") as tmp:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, s0=maps.stokes[0], s1=maps.stokes[1], s2=maps.stokes[2], dolp=maps.dolp,
                                aop_deg=maps.aop_deg)
    write_json(out / "frame.json", content)
    return content
