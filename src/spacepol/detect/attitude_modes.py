"""An attitude the posterior draws left out: a second optimum, as good as the best draw, outside every draw.

A box whose faces look alike under a turn has more than one attitude that makes the same light curve; the one met
most: the box mirrored through the orbit plane, (yaw, pitch, roll) -> (-yaw, pitch, -roll), which swaps port and
starboard (S R(yaw, pitch, roll) S = R(-yaw, pitch, -roll), S = diag(1, -1, 1)). The sun and the site are not
mirrored, so the second optimum lies near that point, in a basin as narrow as the light curve's signal-to-noise
makes it: a local search from the mirrored point stops in one of many shallow optima around it. The check: differential
evolution over the material's prior and the angles within ``BOX_DEG`` of the mirrored best draw; an optimum within
``MARGIN`` of the best draw's log posterior, more than ``SEPARATED`` of the draws' own SD from each draw in some
angle, is a mode the draws miss. Nested sampling with few live points can keep one of two such modes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import differential_evolution

MARGIN = 3.0  # log posterior below the best draw within which a second mode holds >= ~5 % of the first's mass
SEPARATED = 5.0  # draws' SDs (at least MIN_SD_DEG) between the optimum and the nearest draw, in its farthest angle
MIN_SD_DEG = 0.1
BOX_DEG = 15.0  # the search box's half width about the mirrored attitude
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

    def to_json(self) -> dict:
        """The record lightcurve.json carries."""
        return {"attitude": self.attitude, "log_posterior": self.log_posterior, "below_best": self.below_best,
                "finding": self.finding}


def unsampled_mode(log_posterior, names: list[str], bounds, draws: np.ndarray, draws_log_posterior: np.ndarray,
                   rng: np.random.Generator) -> AttitudeMode | None:
    """The mirrored attitude's optimum where it lies outside ``draws`` (S, D) within ``MARGIN`` of their best, or
    None (also where the attitude is not among ``names``). ``log_posterior``: rows (S, D) -> (S,); ``bounds`` (D, 2)."""
    if not all(a in names for a in MIRROR):
        return None
    columns = [names.index(a) for a in MIRROR]
    bounds = np.asarray(bounds, float)
    best_index = int(np.argmax(draws_log_posterior))
    best, best_value = draws[best_index], float(draws_log_posterior[best_index])
    box = bounds.copy()
    for j, sign in zip(columns, MIRROR.values()):
        centre = sign * best[j]
        box[j] = max(bounds[j, 0], centre - BOX_DEG), min(bounds[j, 1], centre + BOX_DEG)

    def negative(x):  # DE's vectorised call: x (D, S)
        value = log_posterior(np.asarray(x, float).T)
        return np.where(np.isfinite(value), -value, 1e300)

    res = differential_evolution(negative, box, popsize=20, maxiter=300, tol=1e-8, vectorized=True, updating="deferred",
                                 polish=True, rng=np.random.default_rng(rng.integers(2**63)))
    value, theta = -float(np.atleast_1d(res.fun)[0]), np.asarray(res.x, float)
    sd = np.maximum(draws[:, columns].std(axis=0), MIN_SD_DEG)
    distance = np.min(np.max(np.abs(draws[:, columns] - theta[columns]) / sd, axis=1))
    if value < best_value - MARGIN or distance <= SEPARATED:
        return None
    attitude = {names[j]: float(theta[j]) for j in columns}
    at = attitude_words(attitude)
    drawn = attitude_words({names[j]: best[j] for j in columns})
    finding = (f"a second attitude ({at} deg) fits {'as well as' if value <= best_value else 'better than'} the best "
               f"draw ({drawn} deg; log posterior {value - best_value:+.1f}) and lies outside every draw: the draws "
               "hold one of two attitudes only, so the attitude's intervals may exclude the truth (more --live points "
               "sample both)")
    return AttitudeMode(attitude, theta, value, best_value - value, finding)
