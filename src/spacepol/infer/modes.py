"""Where the sampler starts: independent searches for the posterior's maximum until they agree.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

SAME_MODE_LOG_POSTERIOR = 1.0
CLOSE_MODES_LOG_POSTERIOR = 10.0  # a distinct mode within this of the best: the posterior may hold both


@dataclass(frozen=True)
class Mode:
    """One local maximum: its log posterior, the parameter vector (priors' order) and how many searches ended there."""

    log_posterior: float
    theta: np.ndarray
    found_by: int = 1


@dataclass
class ModeSearch:
    """The modes the start-point searches found, best first, and whether the best was reached more than once."""

    names: list
    modes: list = field(default_factory=list)
    searches: int = 0
    agreeing: int = 2

    @property
    def best(self) -> Mode:
        """The mode of highest log posterior."""
        return self.modes[0]

    @property
    def agreed(self) -> bool:
        """Whether enough independent searches (``agreeing``, or all of them if fewer) ended in the best mode."""
        return bool(self.modes) and self.best.found_by >= min(self.agreeing, self.searches)

    @property
    def close_modes(self) -> list:
        """Other modes within CLOSE_MODES_LOG_POSTERIOR of the best: the posterior is likely multimodal."""
        return [m for m in self.modes[1:] if self.best.log_posterior - m.log_posterior < CLOSE_MODES_LOG_POSTERIOR]

    def add(self, value: float, theta) -> None:
        """Record one search's optimum: the same mode as one found before when within SAME_MODE_LOG_POSTERIOR."""
        self.searches += 1
        theta = np.asarray(theta, float)
        for j, mode in enumerate(self.modes):
            if abs(mode.log_posterior - value) < SAME_MODE_LOG_POSTERIOR:
                keep = theta if value > mode.log_posterior else mode.theta
                self.modes[j] = Mode(max(value, mode.log_posterior), keep, mode.found_by + 1)
                break
        else:
            self.modes.append(Mode(float(value), theta))
        self.modes.sort(key=lambda m: -m.log_posterior)

    def to_json(self) -> dict:
        """Searches, agreement and every mode with how far it lies below the best (summary.json's ``modes``)."""
        best = self.best.log_posterior
        return {"searches": self.searches, "agreed": self.agreed,
                "modes": [{"log_posterior": m.log_posterior, "below_best": best - m.log_posterior, "found_by": m.found_by,
                           "parameters": dict(zip(self.names, map(float, m.theta)))} for m in self.modes]}

    def findings(self) -> list[str]:
        """Sentences for a report: whether the searches agreed, the other modes and how much worse they are."""
        out = []
        if not self.agreed:
            out.append(f"The start-point searches did not agree: the best mode was found by {self.best.found_by} of "
                       f"{self.searches} independent searches; a better mode may exist (run with another --seed to check).")
        others = self.modes[1:]
        if others:
            out.append(f"{self.searches} independent searches found {len(self.modes)} modes; the walkers start at the best "
                       f"(log posterior {self.best.log_posterior:.1f}, {self.best.found_by} searches); the others lie "
                       + ", ".join(f"{self.best.log_posterior - m.log_posterior:.1f}" for m in others)
                       + " log units below it" + _where(self, others[0]) + ".")
        if self.close_modes:
            out.append(f"MULTIMODAL: {len(self.close_modes)} other mode(s) lie within {CLOSE_MODES_LOG_POSTERIOR:g} log units "
                       "of the best; the chain starts in the best and may not visit them: the posterior reported is that "
                       "of the best mode.")
        return out


def _where(search: ModeSearch, other: Mode) -> str:
    """How the runner-up differs from the best, in the parameters that differ most (relative to the best's size)."""
    best = search.best.theta
    scale = np.maximum(np.abs(best), 1e-3)
    order = np.argsort(-np.abs(other.theta - best) / scale)[:3]
    return " (the nearest: " + ", ".join(f"{search.names[j]} {other.theta[j]:.4g} vs {best[j]:.4g}" for j in order) + ")"


def search_modes(posterior, rng: np.random.Generator, evaluations: int = 3000, min_searches: int = 3,
                 max_searches: int = 6, agreeing: int = 2, search=None) -> ModeSearch:
    """Independent global searches (``search(posterior, rng, evaluations) -> (log posterior, theta)``, by default
    ``optimum.find_optimum_profiled``), each with its own stream drawn from ``rng``, until the best mode has been found by
    ``agreeing`` searches (and at least ``min_searches`` ran), or ``max_searches`` ran."""
    if search is None:
        from .optimum import find_optimum_profiled as search
    result = ModeSearch(list(posterior.priors.names), agreeing=agreeing)
    streams = rng.spawn(max_searches)
    for stream in streams:
        value, theta = search(posterior, stream, evaluations)
        result.add(value, theta)
        if result.searches >= min_searches and result.best.found_by >= agreeing:
            break
    return result
