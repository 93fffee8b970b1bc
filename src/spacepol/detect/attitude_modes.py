"""An attitude the posterior draws left out: an optimum as good as the best draw, or better, outside every draw.

A light curve's posterior over the attitude is rugged: a box whose faces look alike under a turn has more than one
attitude that makes the same curve (the box mirrored through the orbit plane, (yaw, pitch, roll) -> (-yaw, pitch,
-roll), is the one met most), and a curve of high signal-to-noise has basins a degree wide among many shallow optima,
where nested sampling with few live points can keep a wrong one. The check: the log posterior on a grid of attitudes
(``GRID_DEG`` apart) times ``MATERIAL_DRAWS`` of the material's prior, Nelder-Mead from the ``LEADERS`` best attitudes
and from the best draw's mirror, then again from the ``RESTARTS`` best optima with smaller simplexes (a first pass
often stops in a shallow optimum beside the basin); an optimum within ``MARGIN`` of the best draw's log posterior, or
above it, more than ``SEPARATED`` of the draws' own SD from each draw in some angle, is a mode the draws miss.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..infer.simplex import maximize_from

MARGIN = 3.0  # log posterior below the best draw within which a second mode holds >= ~5 % of the first's mass
SEPARATED = 5.0  # draws' SDs (at least MIN_SD_DEG) between the optimum and the nearest draw, in its farthest angle
MIN_SD_DEG = 0.1
BOX_DEG = 15.0  # the half width of the box a missed mode is sampled in (``light_curve_inversion``)
GRID_DEG = 10.0
MATERIAL_DRAWS = 32
LEADERS = 80
RESTARTS = 10
RESTART_SCALES = (0.4, 0.2, 0.1, 0.05)  # of the first simplexes' size
MIRROR = {"yaw_deg": -1.0, "pitch_deg": 1.0, "roll_deg": -1.0}


def attitude_words(attitude: dict) -> str:
    """{angle name: deg} in words: "yaw 12.0, pitch -3.5, roll 0.2"."""
    return ", ".join(f"{name.removesuffix('_deg')} {value:.1f}" for name, value in attitude.items())


@dataclass(frozen=True)
class AttitudeMode:
    """The attitude the draws miss (``attitude``: {angle: deg}), the full parameter row (``theta``), its log
    posterior, how far below the best draw (``below_best``, negative where above) and the finding in words."""

    attitude: dict
    theta: np.ndarray
    log_posterior: float
    below_best: float
    finding: str

    @property
    def far_better(self) -> bool:
        """Above the best draw by more than ``MARGIN``: the draws hold a lesser optimum, not one of two."""
        return self.below_best < -MARGIN

    def to_json(self) -> dict:
        """The record lightcurve.json carries."""
        return {"attitude": self.attitude, "log_posterior": self.log_posterior, "below_best": self.below_best,
                "finding": self.finding}


def unsampled_mode(log_posterior, names: list[str], bounds, draws: np.ndarray, draws_log_posterior: np.ndarray,
                   prior_draws: np.ndarray) -> AttitudeMode | None:
    """The best optimum outside ``draws`` (S, D) within ``MARGIN`` of their best or above it, or None (also where the
    attitude is not among ``names``). ``log_posterior``: rows (S, D) -> (S,); ``bounds`` (D, 2); ``prior_draws``
    (M, D): draws of the prior, whose other parameters the attitude grid is crossed with."""
    if not all(a in names for a in MIRROR):
        return None
    columns = [names.index(a) for a in MIRROR]
    bounds = np.asarray(bounds, float)
    best_index = int(np.argmax(draws_log_posterior))
    best, best_value = draws[best_index], float(draws_log_posterior[best_index])
    mirrored = best.copy()
    mirrored[columns] = np.clip(best[columns] * list(MIRROR.values()), bounds[columns, 0], bounds[columns, 1])
    starts = np.vstack([_grid_leaders(log_posterior, bounds, columns, np.asarray(prior_draws, float)), mirrored])
    scale = (bounds[:, 1] - bounds[:, 0]) / 8.0
    scale[columns] = GRID_DEG / 2.0
    optima, values = maximize_from(log_posterior, starts, scale, bounds)
    again = np.argsort(-np.where(np.isfinite(values), values, -np.inf), kind="stable")[:RESTARTS]
    smaller = np.tile(np.outer(RESTART_SCALES, scale), (len(again), 1))
    polished, polished_values = maximize_from(log_posterior, np.repeat(optima[again], len(RESTART_SCALES), axis=0),
                                              smaller, bounds)
    optima, values = np.vstack([optima, polished]), np.concatenate([values, polished_values])
    sd = np.maximum(draws[:, columns].std(axis=0), MIN_SD_DEG)
    distance = np.array([np.min(np.max(np.abs(draws[:, columns] - x[columns]) / sd, axis=1)) for x in optima])
    kept = np.isfinite(values) & (values >= best_value - MARGIN) & (distance > SEPARATED)
    if not kept.any():
        return None
    pick = int(np.argmax(np.where(kept, values, -np.inf)))
    value, theta = float(values[pick]), optima[pick]
    attitude = {names[j]: float(theta[j]) for j in columns}
    at = attitude_words(attitude)
    drawn = attitude_words({names[j]: best[j] for j in columns})
    mode = AttitudeMode(attitude, theta, value, best_value - value, "")
    if mode.far_better:
        finding = (f"an attitude ({at} deg) fits far better than the best draw ({drawn} deg; log posterior "
                   f"{value - best_value:+.1f}) and lies outside every draw: the exploration kept a lesser optimum, so "
                   "the attitude's intervals exclude the posterior's main mode")
    else:
        finding = (f"a second attitude ({at} deg) fits {'as well as' if value <= best_value else 'better than'} the "
                   f"best draw ({drawn} deg; log posterior {value - best_value:+.1f}) and lies outside every draw: the "
                   "draws hold one of two attitudes only, so the attitude's intervals may exclude the truth (more "
                   "--live points sample both)")
    return replace(mode, finding=finding)


def _grid_leaders(log_posterior, bounds: np.ndarray, columns: list[int], prior_draws: np.ndarray) -> np.ndarray:
    """(LEADERS, D) the best parameter rows of the attitude grid crossed with ``prior_draws``: at each grid attitude
    the best of the draws, then the ``LEADERS`` best attitudes (distinct, so the starts spread over the grid)."""
    axes = [np.arange(lo, hi + 1e-9, GRID_DEG) for lo, hi in bounds[columns]]
    attitudes = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(columns))
    rows = np.repeat(prior_draws[None], len(attitudes), axis=0)
    rows[:, :, columns] = attitudes[:, None, :]
    values = np.asarray(log_posterior(rows.reshape(-1, rows.shape[2])), float).reshape(len(attitudes), -1)
    values = np.where(np.isfinite(values), values, -np.inf)
    best_draw = np.argmax(values, axis=1)
    order = np.argsort(-values[np.arange(len(attitudes)), best_draw], kind="stable")[:LEADERS]
    return rows[order, best_draw[order]]
