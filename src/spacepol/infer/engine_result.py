"""What every engine returns (emcee, NUTS, the paper's GA, nlopt, scipy DE): draws or a best point, and its settings."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

RHAT_TARGET = 1.01  # a sampler waits for ArviZ's rank-normalised split R-hat at most this
ESS_TARGET = 400.0  # and bulk and tail ESS at least this


@dataclass
class EngineResult:
    """What an engine returns: an optimizer's best point and its search history, or a sampler's draws
    (``samples``: draws x chains x D, after burn-in and thinning) with their log posterior; ``info`` holds the
    engine's own settings and diagnostics."""

    method: str
    model: str
    names: list[str]
    best: dict[str, float]  # optimum (optimizers) or MAP sample (emcee), free parameters only
    objective: float  # the engine's objective at ``best`` (lower is better)
    objective_name: str
    n_evaluations: int
    seconds: float
    seed: int
    history: np.ndarray | None = None  # (k, 2): evaluations so far, best objective so far
    samples: np.ndarray | None = None  # (draws, chains, D) posterior samples after burn-in and thinning
    log_prob: np.ndarray | None = None  # (draws, chains)
    info: dict = field(default_factory=dict)

    def best_vector(self) -> np.ndarray:
        """``best`` as a vector in ``names`` order."""
        return np.array([self.best[n] for n in self.names])

    def flat_samples(self) -> np.ndarray:
        """The draws of every chain stacked: (draws x chains, D). An optimizer's result has none (ValueError)."""
        if self.samples is None:
            raise ValueError(f"{self.method} gives a point estimate, not samples")
        return self.samples.reshape(-1, self.samples.shape[-1])

    def to_json(self) -> dict:
        """The result as JSON-ready fields (what ``optimize`` prints)."""
        out = {
            "method": self.method, "model": self.model, "best": self.best,
            "objective": self.objective, "objective_name": self.objective_name,
            "n_evaluations": self.n_evaluations, "seconds": self.seconds, "seed": self.seed,
        }
        out.update({k: v for k, v in self.info.items() if isinstance(v, (int, float, str, bool, list, dict))})
        return out


class History:
    """Best objective against evaluations, recorded as an engine runs."""

    def __init__(self):
        self.evaluations = 0
        self.best = np.inf
        self.best_x = None
        self.points: list[tuple[int, float]] = []

    def record(self, x, values):
        """Count the evaluations of ``values`` at points ``x`` and keep the best so far."""
        values = np.atleast_1d(values)
        x = np.atleast_2d(x)
        self.evaluations += len(values)
        i = int(np.argmin(values))
        if values[i] < self.best:
            self.best, self.best_x = float(values[i]), x[i].copy()
        self.points.append((self.evaluations, self.best))

    def as_array(self):
        """(evaluations so far, best objective so far) per record, as a (k, 2) array."""
        return np.array(self.points, dtype=float)

    def to_result(self, method, objective, model_name, seconds, seed, info) -> EngineResult:
        """The EngineResult of an optimizer that recorded its evaluations here."""
        return EngineResult(
            method=method, model=model_name, names=list(objective.names),
            best=dict(zip(objective.names, map(float, self.best_x))), objective=self.best,
            objective_name=objective.name, n_evaluations=self.evaluations, seconds=seconds,
            seed=-1 if seed is None else seed, history=self.as_array(), info=info,
        )
