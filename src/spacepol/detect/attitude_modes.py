"""An attitude the posterior draws left out: a second optimum, as good as the best draw, outside every draw.

A box whose faces look alike under a turn has more than one attitude that makes the same light curve. The one
found most often: the box mirrored through the orbit plane, (yaw, pitch, roll) -> (-yaw, pitch, -roll), which swaps
port and starboard (S R(yaw, pitch, roll) S = R(-yaw, pitch, -roll), S = diag(1, -1, 1)); the sun and the site are
not mirrored, so the second optimum lies near that point. Nested sampling with few live points can keep one of two
such modes. The check: from the best draw with each combination of the angles' signs flipped, a bounded local
search (Powell) of the log posterior; an optimum within ``MARGIN`` of the best draw that lies more than
``SEPARATED`` of the draws' own SD from each draw in some angle is a mode the draws miss.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

MARGIN = 3.0  # log posterior below the best draw within which a second mode holds >= ~5 % of the first's mass
SEPARATED = 5.0  # draws' SDs (at least MIN_SD_DEG) between the optimum and the nearest draw, in its farthest angle
MIN_SD_DEG = 0.1
EVALUATIONS = 300  # per local search


@dataclass(frozen=True)
class AttitudeMode:
    """The attitude the draws miss (``attitude``: {angle: deg}), the full parameter row (``theta``), its log
    posterior, how far below the best draw (``below_best``, negative where above) and the finding in words."""

    attitude: dict
    theta: np.ndarray
    log_posterior: float
    below_best: float
    finding: str

    def to_json(self) -> dict:
        """The record lightcurve.json carries."""
        return {"attitude": self.attitude, "log_posterior": self.log_posterior, "below_best": self.below_best,
                "finding": self.finding}


def _flipped_starts(best: np.ndarray, columns: list[int], bounds: np.ndarray) -> list[np.ndarray]:
    starts = []
    for signs in itertools.product((1.0, -1.0), repeat=len(columns)):
        if all(s > 0 for s in signs):
            continue
        start = best.copy()
        start[columns] *= signs
        starts.append(np.clip(start, bounds[:, 0], bounds[:, 1]))
    return starts


def unsampled_mode(log_posterior, names: list[str], angles: list[str], bounds, draws: np.ndarray,
                   draws_log_posterior: np.ndarray) -> AttitudeMode | None:
    """The best attitude optimum outside ``draws`` (S, D) within ``MARGIN`` of their best, or None.
    ``log_posterior``: rows (S, D) -> (S,); ``angles``: the names of the attitude columns; ``bounds`` (D, 2)."""
    columns = [names.index(a) for a in angles if a in names]
    if not columns:
        return None
    bounds = np.asarray(bounds, float)
    best_index = int(np.argmax(draws_log_posterior))
    best, best_value = draws[best_index], float(draws_log_posterior[best_index])
    sd = np.maximum(draws[:, columns].std(axis=0), MIN_SD_DEG)

    def negative(x):
        value = float(log_posterior(np.asarray(x, float)[None, :])[0])
        return -value if np.isfinite(value) else 1e300

    found = None
    for start in _flipped_starts(best, columns, bounds):
        res = minimize(negative, start, method="Powell", bounds=bounds, options={"maxfev": EVALUATIONS, "xtol": 1e-3})
        value = -float(res.fun)
        if value < best_value - MARGIN:
            continue
        distance = np.min(np.max(np.abs(draws[:, columns] - res.x[columns]) / sd, axis=1))
        if distance > SEPARATED and (found is None or value > found[0]):
            found = (value, res.x)
    if found is None:
        return None
    value, theta = found
    attitude = {names[j]: float(theta[j]) for j in columns}
    at = ", ".join(f"{k.removesuffix('_deg')} {v:.1f}" for k, v in attitude.items())
    drawn = ", ".join(f"{names[j].removesuffix('_deg')} {best[j]:.1f}" for j in columns)
    finding = (f"a second attitude ({at} deg) fits {'as well as' if value <= best_value else 'better than'} the best "
               f"draw ({drawn} deg; log posterior {value - best_value:+.1f}) and lies outside every draw: the light "
               "curve does not tell the two apart, and the attitude's intervals hold one of them only (more --live "
               "points sample both)")
    return AttitudeMode(attitude, theta, value, best_value - value, finding)
