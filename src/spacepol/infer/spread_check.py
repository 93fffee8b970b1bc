"""Whether importance draws hold the posterior's whole width: emcee walkers started inside them, left to spread.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass

import emcee
import numpy as np

from .engines.emcee_sampler import default_walkers, ridge_moves
from .sampling_space import SamplingSpace

# walker steps; the SDs compared are those of the second half. On a metal's n-k band (DOP with a 100 %-noise BRDF,
# draws trusted by Pareto k with SDs 0.71-0.84 of emcee's) 1,000 steps showed growths of 1.11-1.78, 2,000 of 1.10-1.66;
# on near-Gaussian posteriors (the 84-point paper set, 8 seeds; PTFE's 278 geometries, 4 seeds) 2,000 steps gave
# 0.96-1.04 (batch-means SE 0.01-0.02)
STEPS = 2000
MIN_WALKERS = 64
BATCHES = 5
# a chain SD this many times the draws' refuses them: draws more than 7 % narrower than what the walkers find, placed
# between the growth correct draws show (<= 1.04) and the 10 % shortfall no accepted posterior may have
MAX_SD_GROWTH = 1.08
# a growth between this and MAX_SD_GROWTH after STEPS is not yet a decision: above the 1.04 right draws reach, within
# the ratio's Monte-Carlo SE (0.02-0.04) of the limit, where a band's walkers may still be on their way out (the metal
# band, draws at 0.86 of emcee's SD of n: 1.07 after 2,000 steps, 1.15 after 4,000). The walkers go on for STEPS
# more and the later half decides
EXTEND_ABOVE = 1.05
# walkers started inside right draws start in the posterior's equilibrium and stay as wide as the draws from the first
# step, so a growth far beyond the limit part-way through is already a decision: at these steps the check refuses
# where the widest ratio exceeds EARLY_REFUSAL and lies 3 SEs above MAX_SD_GROWTH. Measured: right draws 1.00-1.05
# after 250 steps (SE 0.01-0.04); the metal band's draws 1.46-1.51 after 250 and 500 steps, 1.34 after 2,000
EARLY_LOOKS = (250, 500, 1000)
EARLY_REFUSAL = 1.25
# Pareto k at or below this: the weights' tail is bounded, and the walkers are not run (``SpreadCheck.bounded``).
# Measured (``benchmarks/laplace_ridges.py``): on the curved bands k 0.35-0.67; on the 84-point paper set -0.22 to -0.10
BOUNDED_K = 0.0


@dataclass(frozen=True)
class SpreadCheck:
    """The outcome: per declared parameter (``names``) the chain's SD over the draws' SD (``ratios``), the ratio's
    Monte-Carlo standard error, the steps and walkers run."""

    names: tuple[str, ...]
    ratios: np.ndarray
    standard_error: np.ndarray
    steps: int
    walkers: int
    bounded_by: float | None = None  # the draws' Pareto k where the walkers were not run (``bounded``)

    @classmethod
    def bounded(cls, names, pareto_k: float) -> SpreadCheck:
        """The check where the weights' tail is bounded (Pareto k <= ``BOUNDED_K``): no walkers are run. Bounded
        weights p/q give importance sampling's moments a finite variance; draws too narrow for the posterior leave
        mass where the proposal is thin, and the draws that reach its edge then carry the largest weights (k > 0)."""
        nothing = np.full(len(names), np.nan)
        return cls(names=tuple(names), ratios=nothing, standard_error=nothing, steps=0, walkers=0,
                   bounded_by=float(pareto_k))

    @property
    def widest(self) -> tuple[str | None, float | None]:
        """(the parameter whose SD grew most, its ratio); (None, None) where the walkers were not run."""
        if self.bounded_by is not None:
            return None, None
        j = int(np.argmax(self.ratios))
        return self.names[j], float(self.ratios[j])

    @property
    def clearly_refused(self) -> bool:
        """Whether a parameter's SD grew beyond ``EARLY_REFUSAL`` and 3 SEs beyond ``MAX_SD_GROWTH``: a refusal that
        more steps would not undo (walkers started inside right draws do not spread)."""
        return bool(self.bounded_by is None and np.any((self.ratios > EARLY_REFUSAL)
                                                       & (self.ratios - 3 * self.standard_error > MAX_SD_GROWTH)))

    @property
    def refusal(self) -> str:
        """Why the draws are too narrow, in words ("" where no parameter's SD grew beyond ``MAX_SD_GROWTH``)."""
        if self.bounded_by is not None:
            return ""
        grown = [f"{n} {r:.2f}x" for n, r in zip(self.names, self.ratios) if not r <= MAX_SD_GROWTH]
        if not grown:
            return ""
        return (f"emcee walkers started inside the importance draws spread beyond them in {self.steps} steps "
                f"(chain SD over the draws' SD: {', '.join(grown)} > {MAX_SD_GROWTH:g}): the draws are narrower than "
                "the posterior")

    def to_json(self) -> dict:
        """Per parameter the ratio and its standard error, and the run's size (where the walkers were not run, the
        Pareto k that made them unnecessary)."""
        if self.bounded_by is not None:
            return {"walkers_run": False, "pareto_k": self.bounded_by, "bounded_k": BOUNDED_K,
                    "why": f"Pareto k {self.bounded_by:.2f} <= {BOUNDED_K:g}: the importance weights are bounded"}
        return {"walkers_run": True, "sd_ratio": dict(zip(self.names, map(float, self.ratios))),
                "sd_ratio_se": dict(zip(self.names, map(float, self.standard_error))),
                "steps": self.steps, "walkers": self.walkers, "limit": MAX_SD_GROWTH}


def weighted_sd(theta: np.ndarray, log_weights: np.ndarray) -> np.ndarray:
    """Per column, the SD of draws ``theta`` (S, D) under log weights (S,), any normalisation; -inf weighs 0."""
    keep = np.isfinite(log_weights)
    w = np.exp(log_weights[keep] - np.max(log_weights[keep]))
    w /= w.sum()
    mean = w @ theta[keep]
    return np.sqrt(w @ (theta[keep] - mean) ** 2)


def _starts(space: SamplingSpace, sample, rng: np.random.Generator, walkers: int) -> np.ndarray:
    """``walkers`` distinct starting points in z, resampled from the weighted draws; a draw picked twice is moved by
    1e-6 of the draws' SD, as emcee needs linearly independent walkers."""
    z = space.to_z(sample.theta[sample.resample(rng, walkers)])
    sd = np.std(z, axis=0) + 1e-12
    _, first = np.unique(z, axis=0, return_index=True)
    repeated = np.setdiff1d(np.arange(walkers), first)
    z[repeated] += 1e-6 * sd * rng.standard_normal((len(repeated), z.shape[1]))
    return z


def spread_check(posterior, sample, rng: np.random.Generator, steps: int = STEPS,
                 walkers: int | None = None, skip_bounded: bool = True) -> SpreadCheck:
    """Run emcee's ensemble from ``sample`` (an ``laplace.ImportanceSample`` of ``posterior``) and compare SDs; with
    ``skip_bounded``, not where the weights' Pareto k is at most ``BOUNDED_K`` (``SpreadCheck.bounded``)."""
    if skip_bounded and sample.pareto_k <= BOUNDED_K:
        return SpreadCheck.bounded(posterior.names, sample.pareto_k)
    space = SamplingSpace(posterior.priors)
    ndim = posterior.ndim
    walkers = walkers or max(MIN_WALKERS, default_walkers(ndim))
    if hasattr(getattr(posterior, "likelihood", None), "exact_sizes"):
        posterior.likelihood.exact_sizes.add(walkers // 2)  # emcee evaluates half the ensemble at a time
        posterior.likelihood.expect_sets(walkers * steps)
    log_prob = space.log_prob(posterior)
    sampler = emcee.EnsembleSampler(walkers, ndim, log_prob, vectorize=True, moves=ridge_moves())
    sampler.log_prob_fn = log_prob  # called directly: emcee's wrapper prints every walker on an exception
    sampler.random_state = np.random.RandomState(int(rng.integers(2**32))).get_state()
    draws_sd = weighted_sd(sample.theta, sample.log_weights)
    state = _starts(space, sample, rng, walkers)
    for look in [*(s for s in EARLY_LOOKS if s < steps), steps]:
        state = sampler.run_mcmc(state, look - sampler.iteration, progress=False)
        check = _compared(sampler, space, posterior.names, draws_sd)
        if look < steps and check.clearly_refused:
            return check
    if EXTEND_ABOVE <= check.widest[1] <= MAX_SD_GROWTH:  # undecided: the walkers go on
        sampler.run_mcmc(None, steps, progress=False)
        check = _compared(sampler, space, posterior.names, draws_sd)
    return check


def _compared(sampler, space: SamplingSpace, names, draws_sd: np.ndarray) -> SpreadCheck:
    """The SDs of the second half of the walkers' run so far over the draws' SDs, with batch-means SEs."""
    steps, ndim = sampler.iteration, len(names)
    chain = space.to_theta(sampler.get_chain(discard=steps // 2))  # (steps/2, walkers, D)
    ratios = chain.reshape(-1, ndim).std(axis=0) / draws_sd
    # batch means: the SD of each of BATCHES consecutive stretches of the kept steps, their scatter over sqrt(BATCHES)
    batches = np.array([b.reshape(-1, ndim).std(axis=0) for b in np.array_split(chain, BATCHES)]) / draws_sd
    se = batches.std(axis=0, ddof=1) / np.sqrt(BATCHES)
    return SpreadCheck(names=tuple(names), ratios=ratios, standard_error=se, steps=steps, walkers=sampler.nwalkers)
