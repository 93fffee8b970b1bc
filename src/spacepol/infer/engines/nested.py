"""Nested sampling with nautilus (Lange 2023, MNRAS 525, 3181): the posterior and the Bayesian evidence ln Z.

Chosen over dynesty by measurement (``benchmarks/nested_choice.py``, figures in docs/benchmarks-log.md): on the paper's
posterior nautilus gave more effective draws per second, evaluating the likelihood in the batches the compiled
likelihood is built for.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass

import numpy as np
from scipy.special import logsumexp

from ..engine_result import EngineResult
from .base import SAMPLER, Engine
from .stall_guard import CallClock, stall_guard


def replicate_draws(points, log_w, rng: np.random.Generator, size: int) -> np.ndarray:
    """``size`` indices of equally weighted draws from weighted points (systematic resampling)."""
    w = np.exp(log_w - logsumexp(log_w))
    positions = (rng.random() + np.arange(size)) / size
    return np.minimum(np.searchsorted(np.cumsum(w), positions), len(points) - 1)


def kish_draws(log_w) -> float:
    """How many independent draws weighted points are worth (Kish: 1 / sum of the squared normalised weights)."""
    w = np.exp(np.asarray(log_w, float) - logsumexp(log_w))
    return float(1.0 / np.sum(w**2))


# after the exploration, at most this many likelihood calls per live point go into reaching the effective draws
SAMPLING_CALLS_PER_LIVE_POINT = 100
# likelihood calls per live point without a new shell that end an exploration where it stands
STUCK_CALLS_PER_LIVE_POINT = 100


@dataclass(frozen=True)
class NestedOutcome:
    """How a nautilus run ended: whether its points reached the effective draws asked for, and whether its
    exploration ended by nautilus' own criterion (False: no new shell in ``STUCK_CALLS_PER_LIVE_POINT`` calls per
    live point, so the run was sampled from the shells it had)."""

    draws_reached: bool
    explored: bool


def _explore(sampler, stuck_calls: int) -> bool:
    """Run ``sampler``'s exploration in steps of one live set's worth of calls, to its end or until ``stuck_calls``
    calls pass without a new shell; then end it where it stands. Whether it ended by nautilus' own criterion. The
    steps change nothing else: nautilus keeps its whole state between ``run`` calls."""
    shells, since = len(sampler.bounds), sampler.n_like
    while not sampler.explored:
        sampler.run(n_eff=0, discard_exploration=True, verbose=False, n_like_max=sampler.n_like + sampler.n_live)
        if len(sampler.bounds) != shells:
            shells, since = len(sampler.bounds), sampler.n_like
        elif not sampler.explored and sampler.n_like - since >= stuck_calls:
            # f_live is a fraction, so any bound above 1 ends the exploration at the next batch
            sampler.run(f_live=2.0, n_eff=0, discard_exploration=True, verbose=False)
            return False
    sampler.run(n_eff=0, discard_exploration=True, verbose=False)  # every shell holds a point, as one run leaves it
    return True


def explore_then_sample(sampler, effective_draws: int, clock: CallClock, what: str,
                        calls_per_live_point: int = SAMPLING_CALLS_PER_LIVE_POINT,
                        stuck_calls_per_live_point: int = STUCK_CALLS_PER_LIVE_POINT) -> NestedOutcome:
    """Run a nautilus ``sampler``'s exploration to its end, then sample its shells until the points are worth
    ``effective_draws`` or ``calls_per_live_point`` likelihood calls per live point more have been spent. The cap
    matters where a posterior is far narrower than the last shell: there the points gain almost no effective draws
    per call, and an uncapped run goes on for hours. An exploration that adds no shell in
    ``stuck_calls_per_live_point`` calls per live point is ended where it stands (a thin curved ridge the shells'
    ellipsoids cannot follow: nautilus rejects every new bound as no smaller than the last, and would call the
    likelihood without end). ``clock``: ticked by the sampler's likelihood; a run that stops making progress stops
    with ``SamplerStalled`` naming ``what`` (``stall_guard``)."""
    with stall_guard(clock, what, sampler):
        explored = _explore(sampler, stuck_calls_per_live_point * sampler.n_live)
        sampler.run(n_eff=effective_draws, discard_exploration=True, verbose=False,
                    n_like_max=sampler.n_like + calls_per_live_point * sampler.n_live)
    return NestedOutcome(sampler.n_eff >= effective_draws, explored)


def combine_evidence(log_z: np.ndarray) -> tuple[float, float]:
    """(ln of the mean evidence, its standard error) of independent replicates' ln Z."""
    log_z = np.asarray(log_z, float)
    mean = float(logsumexp(log_z) - np.log(log_z.size))
    z = np.exp(log_z - mean)  # relative to the mean: the SE of ln(mean Z) is SE(Z)/mean Z
    return mean, float(np.std(z, ddof=1) / np.sqrt(z.size)) if z.size > 1 else float("nan")


def sample_nested(posterior, rng: np.random.Generator, live: int = 500, replicates: int = 3, networks: int = 1,
                  effective_draws: int = 4000, max_draws_per_replicate: int = 2000, progress: bool = False) -> EngineResult:
    """``replicates`` nautilus runs with ``live`` live points and ``networks`` networks, each until
    ``effective_draws`` effective draws; draws (per replicate at most ``max_draws_per_replicate``) and ln Z."""
    import sys

    from nautilus import Sampler

    start = time.perf_counter()
    priors = posterior.priors
    clock = CallClock()

    def log_likelihood(theta):
        clock.tick()
        value = posterior.log_likelihood(np.atleast_2d(theta))
        return np.where(np.isfinite(value), value, -1e300)  # nautilus needs finite numbers

    chains, log_z, effective, calls, ended_early = [], [], [], 0, 0
    for r in range(replicates):
        sampler = Sampler(priors.rescale, log_likelihood, n_dim=priors.ndim, n_live=live, n_networks=networks,
                          vectorized=True, seed=int(rng.integers(2**31)))
        what = f"replicate {r + 1} of {posterior.likelihood.model.name}"
        explored = explore_then_sample(sampler, effective_draws, clock, what).explored
        ended_early += not explored
        points, log_w, log_l = sampler.posterior()
        effective.append(kish_draws(log_w))
        log_z.append(float(sampler.log_z))
        calls += int(sampler.n_like)
        chains.append((points, log_w, log_l))
        if progress:
            print(f"  nested sampling {r + 1}/{replicates}: ln Z {sampler.log_z:.3f}, {effective[-1]:.0f} effective draws, "
                  f"{time.perf_counter() - start:.0f} s{'' if explored else ' (exploration ended where it stood: no new shell)'}",
                  file=sys.stderr, flush=True)
    per_chain = int(min(max_draws_per_replicate, min(effective)))
    samples, log_prob = [], []
    for points, log_w, log_l in chains:
        idx = replicate_draws(points, log_w, rng, per_chain)
        rng.shuffle(idx)
        samples.append(points[idx])
        log_prob.append(log_l[idx] + priors.ln_prob(points[idx]))
    samples, log_prob = np.stack(samples, axis=1), np.stack(log_prob, axis=1)  # (draws, chains, D), (draws, chains)
    value, error = combine_evidence(log_z)
    best = samples.reshape(-1, priors.ndim)[int(np.argmax(log_prob))]
    return EngineResult(method="nested", model=posterior.likelihood.model.name, names=list(posterior.names),
                        best=dict(zip(posterior.names, map(float, best))), objective=-float(log_prob.max()),
                        objective_name="negative_log_posterior", n_evaluations=calls,
                        seconds=time.perf_counter() - start, seed=-1, samples=samples, log_prob=log_prob,
                        info={"sampler": "nautilus", "live": live, "replicates": replicates, "networks": networks,
                              "log_evidence": value, "log_evidence_error": error, "log_evidence_replicates": log_z,
                              "effective_draws_per_replicate": effective, "draws_per_replicate": per_chain,
                              "likelihood_calls": calls, "explorations_ended_early": ended_early})


def missed_mode(posterior, draws: EngineResult, rng: np.random.Generator) -> dict | None:
    """Whether a global search (``optimum.find_optimum``) finds a log posterior far above every draw nested sampling
    returned: a mode its live points never reached (on PTFE's ridge model a corner of the prior box 10 log units up,
    holding ~e^11 times the mass of the mode found). "Far": more than 3 + D/2 above the best draw (the best of
    thousands of draws from a D-dimensional posterior lies within ~D/2 of its mode). None where nothing was missed;
    else the search's value and point and a finding in words: ln Z then covers only the modes found."""
    from ..optimum import find_optimum

    value, theta = find_optimum(posterior, rng)
    best = float(np.max(draws.log_prob))
    margin = 3.0 + 0.5 * posterior.ndim
    if not np.isfinite(value) or value <= best + margin:
        return None
    at = ", ".join(f"{n} {v:.4g}" for n, v in zip(posterior.names, theta))
    return {"log_posterior": float(value), "best_sampled": best, "at": dict(zip(posterior.names, map(float, theta))),
            "finding": (f"nested sampling missed a mode: a global search reaches log posterior {value:.2f} at ({at}), "
                        f"{value - best:.1f} above every draw it returned; its ln Z covers only the modes it found "
                        "(use emcee, which starts from the best mode, and compare)")}


class Nested(Engine):
    """Nested sampling (nautilus): the posterior and the evidence ln Z with its error from independent replicates
    (``engines.nested``)."""

    name, kind = "nested", SAMPLER
    description = "nested sampling (nautilus): posterior and log evidence with its error"

    def run(self, posterior, rng, live: int = 500, replicates: int = 3, networks: int = 1, effective_draws: int = 4000,
            progress: bool = False):
        """Draws and ln Z (``engines.nested.sample_nested``)."""
        draws = sample_nested(posterior, rng, live=live, replicates=replicates, networks=networks,
                              effective_draws=effective_draws, progress=progress)
        missed = missed_mode(posterior, draws, rng)
        if missed is not None:
            draws.info["missed_mode"] = missed
            if progress:
                print(f"  {missed['finding']}", file=sys.stderr, flush=True)
        return draws
