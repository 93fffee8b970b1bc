"""Nelder-Mead from many starts at once: every simplex steps together, so each step is one batched call of the
objective (rows (N, D) -> (N,)) instead of one call per point.

A vectorised model costs nearly the same for forty parameter sets as for one, so forty local searches in lock step
cost little more than one; scipy's ``minimize`` calls the objective one point at a time. The steps are scipy's
(reflection 1, expansion 2, contraction 1/2, shrink 1/2), the points clipped to the bounds.
"""

from __future__ import annotations

import numpy as np


def maximize_from(f, starts: np.ndarray, scale: np.ndarray, bounds: np.ndarray, max_steps: int = 3000,
                  relative_tolerance: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """The local maxima of ``f`` reached from each row of ``starts`` (K, D): (K, D) points and their (K,) values.
    Each start's first simplex spans ``scale`` ((D,) or one row per start, (K, D)) along the axes; a simplex stops
    when its values agree within ``relative_tolerance`` (relative to the best, plus one) or after ``max_steps``
    steps. ``bounds``: (D, 2)."""
    starts = np.atleast_2d(np.asarray(starts, float))
    count, dim = starts.shape
    lower, upper = np.asarray(bounds, float).T

    def cost(rows):  # minimised; non-finite values rank last. Every point is clipped to the bounds before it is costed
        value = -np.asarray(f(rows), float)
        return np.where(np.isfinite(value), value, np.inf)

    simplex = np.repeat(starts[:, None, :], dim + 1, axis=1)
    simplex[:, 1:, :] += np.eye(dim)[None] * np.broadcast_to(np.asarray(scale, float), (count, dim))[:, None, :]
    simplex = np.clip(simplex, lower, upper)
    costs = cost(simplex.reshape(-1, dim)).reshape(count, dim + 1)
    for _ in range(max_steps):
        order = np.argsort(costs, axis=1, kind="stable")
        simplex = np.take_along_axis(simplex, order[:, :, None], axis=1)
        costs = np.take_along_axis(costs, order, axis=1)
        spread = costs[:, -1] - costs[:, 0]
        settled = spread <= relative_tolerance * (1.0 + np.abs(costs[:, 0]))
        moving = np.flatnonzero(~settled & np.isfinite(costs[:, 0]))
        if not len(moving):
            break
        _step(simplex, costs, moving, cost, lower, upper)
    best = np.argmin(costs, axis=1)
    rows = np.arange(count)
    return simplex[rows, best], -costs[rows, best]


def _step(simplex, costs, moving, cost, lower, upper) -> None:
    """One Nelder-Mead step of the simplexes ``moving`` (sorted, best first), in place."""
    dim = simplex.shape[2]
    centre = simplex[moving, :-1].mean(axis=1)
    worst, worst_cost = simplex[moving, -1], costs[moving, -1]
    best_cost, second_worst_cost = costs[moving, 0], costs[moving, -2]
    reflected = np.clip(2.0 * centre - worst, lower, upper)
    reflected_cost = cost(reflected)
    expand = reflected_cost < best_cost
    outside = ~expand & (reflected_cost >= second_worst_cost) & (reflected_cost < worst_cost)
    inside = ~expand & (reflected_cost >= worst_cost)
    direction = centre - worst
    trial = np.where(expand[:, None], centre + 2.0 * direction,
                     np.where(outside[:, None], centre + 0.5 * direction, centre - 0.5 * direction))
    trial = np.clip(trial, lower, upper)
    needed = expand | outside | inside
    trial_cost = np.full(len(moving), np.inf)
    if needed.any():
        trial_cost[needed] = cost(trial[needed])
    new, new_cost = worst.copy(), worst_cost.copy()
    take_reflected = (~needed) | (expand & ~(trial_cost < reflected_cost))
    take_trial = (expand & (trial_cost < reflected_cost)) | (outside & (trial_cost <= reflected_cost)) | (
        inside & (trial_cost < worst_cost))
    new[take_reflected], new_cost[take_reflected] = reflected[take_reflected], reflected_cost[take_reflected]
    new[take_trial], new_cost[take_trial] = trial[take_trial], trial_cost[take_trial]
    simplex[moving, -1], costs[moving, -1] = new, new_cost
    shrinking = moving[(outside | inside) & ~take_trial]
    if len(shrinking):
        best = simplex[shrinking, :1]
        simplex[shrinking, 1:] = best + 0.5 * (simplex[shrinking, 1:] - best)
        costs[shrinking, 1:] = cost(simplex[shrinking, 1:].reshape(-1, dim)).reshape(len(shrinking), dim)
