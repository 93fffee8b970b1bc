"""Grids of panels with a fixed layout.

Constrained layout measures every tick label of every panel on every draw: on the tens of panels of a
full-Mueller fit it costs several times the drawing itself. A grid of
like panels needs no solver: margins and gaps in inches leave room for the labels.
"""

from __future__ import annotations

import textwrap

from matplotlib.figure import Figure


class HandLaidFigure(Figure):
    """A Figure whose panels were placed by `panel_grid`: `io.atomic.save_figure` draws it once, without the
    tight-bbox pass (any layout engine, even a placeholder, makes matplotlib draw twice)."""

    laid_out_by_hand = True


def panel_grid(rows: int, cols: int, *, panel_in: tuple[float, float] = (3.2, 2.8),
               gap_in: tuple[float, float] = (0.7, 0.6), margin_in: tuple[float, float, float, float] = (0.75, 0.6, 0.55, 0.2),
               fig: Figure | None = None, **subplots_kw):
    """A ``rows`` x ``cols`` grid of panels, each ``panel_in`` (width, height) inches including its share of the
    gaps; ``gap_in`` (horizontal, vertical) leaves room for each panel's tick labels, y label and title,
    ``margin_in`` (left, bottom, top, right) for the outer labels and the title (`top_title`). Returns
    (figure, 2-D axes array); ``subplots_kw`` go to ``Figure.subplots`` (sharex, sharey)."""
    left, bottom, top, right = margin_in
    width = cols * panel_in[0] + left + right - gap_in[0]
    height = rows * panel_in[1] + bottom + top - gap_in[1]
    if fig is None:
        fig = HandLaidFigure(figsize=(width, height))
    else:
        width, height = fig.get_size_inches()
    axis_w = max((width - left - right - (cols - 1) * gap_in[0]) / cols, 0.1)
    axis_h = max((height - bottom - top - (rows - 1) * gap_in[1]) / rows, 0.1)
    axes = fig.subplots(rows, cols, squeeze=False, gridspec_kw=dict(
        left=left / width, right=1 - right / width, bottom=bottom / height, top=1 - top / height,
        wspace=gap_in[0] / axis_w, hspace=gap_in[1] / axis_h), **subplots_kw)
    return fig, axes


def margin_colorbar(fig: Figure, mappable, label: str, from_right_in: float, bottom: float, height: float):
    """A colorbar 0.15 in wide in the figure's right margin, its left edge ``from_right_in`` inches from the right
    edge, spanning ``bottom`` to ``bottom + height`` of the figure's height (stealing no width from the panels)."""
    width_in = fig.get_size_inches()[0]
    return fig.colorbar(mappable, cax=fig.add_axes((1 - from_right_in / width_in, bottom, 0.15 / width_in, height)),
                        label=label)


def top_title(fig: Figure, text: str, fontsize: float = 9) -> None:
    """The figure's title 0.1 in below its top edge (suptitle's default, a fraction of the height, falls into
    the top panels of a tall figure), wrapped to the figure's width (a narrow grid would cut a long title)."""
    width_in, height_in = fig.get_size_inches()
    chars_per_line = max(20, int(width_in * 72 / (0.55 * fontsize)))  # a character is ~0.55 em wide
    fig.suptitle(textwrap.fill(text, chars_per_line), fontsize=fontsize, y=1 - 0.1 / height_in, va="top")
