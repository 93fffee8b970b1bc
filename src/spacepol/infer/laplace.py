"""A posterior from its mode: a Gaussian (Laplace) approximation in the samplers' coordinates, corrected by
Pareto-smoothed importance sampling (a Student-t proposal; an adapted mixture in the declared parameters where a
parameter piles at a bound), trusted only where Pareto k <= 0.7 with 400 effective draws and the weights have not
collapsed onto the mode; the caller's walkers' check (``spread_check``) guards what Pareto k cannot see.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass

import arviz as az
import numpy as np
from scipy.optimize import minimize
from scipy.special import logsumexp
from scipy.stats import multivariate_t

from .diagnostics import PARETO_K_LIMIT, loo_fields
from .posterior import Posterior
from .psis import logsumexp_rows, psis_log_weights
from .sampling_space import SamplingSpace
from .spread_check import BOUNDED_K, weighted_sd

MIN_EFFECTIVE_DRAWS = 400  # as emcee's ESS target
PROPOSAL_DF = 5.0
ADAPTATIONS = 8  # at most this many moment-matching steps of the declared-parameter proposal
# the weighted draws' SD of each coordinate in the sampling space z, over the Laplace SD there, below which the weights
# are taken to have collapsed onto the mode (see the module's step 6)
MIN_WIDTH_RATIO = 0.75
MAX_DRAWS = 10000  # a trusted proposal short of the effective draws wanted is drawn from again, up to this many in all
# effective draws wanted where the walkers will compare SDs with the draws' (Pareto k above ``BOUNDED_K``): every ratio
# carries the draws' own SD error, ~1 / sqrt(2 x effective draws) (3 % at 528, PTFE's four wavelengths from 2,000
# draws), and the widest of many ratios then reaches the check's undecided band with right draws more often; at 1,500
# it is ~2 %, at most the walkers' own SE after 2,000 steps (the internals page)
WIDTH_EFFECTIVE_DRAWS = 1500


def _trusted(pareto_k: float, effective_draws: float) -> bool:
    """The gate on importance weights: Pareto k <= 0.7 and at least 400 effective draws."""
    return pareto_k <= PARETO_K_LIMIT and effective_draws >= MIN_EFFECTIVE_DRAWS


@dataclass
class ImportanceSample:
    """Draws from a proposal near the posterior with their Pareto-smoothed weights.

    ``theta``: (S, D) draws in the declared parameters; ``log_weights``: (S,) smoothed, normalised (log sum
    exp = 0); ``raw_log_weights``: (S,) log p | y - log q before smoothing, in the proposal's coordinates (z or theta; for LOO); ``log_prob``: (S,) the
    log posterior in the declared parameters (as ``Posterior.log_prob``); ``pareto_k`` and ``effective_draws``
    of the weights; ``mode``: the posterior's mode in theta; ``proposal``: what the draws came from, in words;
    ``width_ratio``: the smallest over coordinates of the weighted draws' SD in the sampling space over the Laplace SD."""

    theta: np.ndarray
    log_weights: np.ndarray
    raw_log_weights: np.ndarray
    log_prob: np.ndarray
    pareto_k: float
    effective_draws: float
    mode: np.ndarray
    proposal: str = ""
    width_ratio: float = 1.0

    @property
    def reliable(self) -> bool:
        """Whether the weighted draws stand for the posterior: k <= 0.7, effective draws >= 400, and no coordinate
        narrower than ``MIN_WIDTH_RATIO`` x its Laplace SD in the sampling space (``width_ratio``, the smallest ratio)."""
        return not self.refusal

    @property
    def refusal(self) -> str:
        """The checks of ``reliable`` that failed, with their figures, in words ("" where it is reliable)."""
        failed = []
        if not self.pareto_k <= PARETO_K_LIMIT:
            failed.append(f"Pareto k {self.pareto_k:.2f} > {PARETO_K_LIMIT:g}")
        if not self.effective_draws >= MIN_EFFECTIVE_DRAWS:
            failed.append(f"{self.effective_draws:.0f} effective draws < {MIN_EFFECTIVE_DRAWS}")
        if not self.width_ratio >= MIN_WIDTH_RATIO:
            failed.append(f"a coordinate's weighted SD {self.width_ratio:.2f} x its Laplace SD < {MIN_WIDTH_RATIO:g}, "
                          "the weights collapsed onto the mode")
        return "; ".join(failed)

    @property
    def log_evidence(self) -> tuple[float, float]:
        """(ln Z, its standard error): Z = the mean over the draws of p(theta, y) / q(theta), the unsmoothed weights
        (draws where the posterior is zero count as zero), an unbiased estimate of the evidence, and the delta
        method's error of its log. The weights' Pareto k bounds this estimate's variance as it bounds the posterior
        moments': it is to be used where the sample is ``reliable`` (k <= 0.7; Vehtari et al. 2024, sec. 6)."""
        raw = np.where(np.isnan(self.raw_log_weights), -np.inf, self.raw_log_weights)
        top = float(np.max(raw))
        w = np.exp(raw - top)
        mean = float(np.mean(w))
        return top + float(np.log(mean)), float(np.std(w) / (np.sqrt(len(w)) * mean))

    def resample(self, rng: np.random.Generator, draws: int | None = None) -> np.ndarray:
        """Indices of ``draws`` equally weighted draws (systematic resampling of the smoothed weights)."""
        draws = len(self.theta) if draws is None else draws
        cumulative = np.cumsum(np.exp(self.log_weights - logsumexp(self.log_weights)))
        positions = (rng.random() + np.arange(draws)) / draws
        return np.minimum(np.searchsorted(cumulative, positions), len(self.theta) - 1)


def scale_ridge(posterior: Posterior) -> str:
    """Why no Gaussian can stand for this posterior by construction, in words ("" where none is known): every fitted
    observable is a ratio of intensities (DOP, q and u, m_ij: ``Observable.scale_free``) and two or more free
    parameters scale lobes (``Effect.intensity``), so the data see only their ratios and the posterior is a ridge
    along their common scale, cut only by the priors."""
    likelihood = posterior.likelihood
    free = set(posterior.names)
    scales = [e.intensity for e in likelihood.model.effects if e.intensity in free]
    if len(scales) < 2 or not all(o.scale_free for o in likelihood.objects):
        return ""
    return (f"the fitted observables ({', '.join(o.name for o in likelihood.objects)}) are ratios of intensities, so they "
            f"see {', '.join(scales)} only through their ratios: the posterior is a ridge along their common scale, "
            "which a Gaussian at the mode cannot hold")


def _polish_mode(log_prob_z, z0: np.ndarray) -> np.ndarray:
    """The maximum of the batched log density nearest ``z0`` (L-BFGS, central-difference gradients: 2D + 1 rows
    per call)."""
    d = z0.size

    def value_and_gradient(z):
        h = 1e-5 * np.maximum(1.0, np.abs(z))
        rows = np.repeat(z[None, :], 2 * d + 1, axis=0)
        rows[1 : d + 1] += np.diag(h)
        rows[d + 1 :] -= np.diag(h)
        values = log_prob_z(rows)
        if not np.isfinite(values[0]):
            return 1e300, np.zeros(d)
        grad = (values[1 : d + 1] - values[d + 1 :]) / (2 * h)
        return -float(values[0]), -np.where(np.isfinite(grad), grad, 0.0)

    res = minimize(value_and_gradient, z0, jac=True, method="L-BFGS-B", options={"maxiter": 2000})
    return res.x if res.fun <= value_and_gradient(z0)[0] else z0


def _hessian(log_prob_z, z: np.ndarray, steps: np.ndarray) -> np.ndarray:
    """The Hessian of the batched log density at z by central differences (one call of 2D^2 + 1 rows)."""
    d = z.size
    step = np.diag(steps)  # row j: the step along axis j
    rows = [z]
    for j in range(d):
        rows += [z + step[j], z - step[j]]
    pairs = [(j, k) for j in range(d) for k in range(j + 1, d)]
    for j, k in pairs:
        for sj, sk in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
            rows.append(z + sj * step[j] + sk * step[k])
    values = log_prob_z(np.array(rows))
    centre, axis, cross = values[0], values[1 : 1 + 2 * d].reshape(d, 2), values[1 + 2 * d :].reshape(-1, 4)
    h = np.zeros((d, d))
    h[np.diag_indices(d)] = (axis[:, 0] + axis[:, 1] - 2 * centre) / steps**2
    for (j, k), (pp, pm, mp, mm) in zip(pairs, cross):
        h[j, k] = h[k, j] = (pp - pm - mp + mm) / (4 * steps[j] * steps[k])
    return h


class _Mixture:
    """A mixture of scipy multivariate t's: draws and log density."""

    def __init__(self, components, weights):
        self.components, self.weights = list(components), np.asarray(weights, float)

    def rvs(self, draws: int, rng: np.random.Generator) -> np.ndarray:
        """``draws`` rows, each component contributing a multinomial share, in random order."""
        counts = rng.multinomial(draws, self.weights)
        parts = [np.atleast_2d(c.rvs(size=m, random_state=rng)) for c, m in zip(self.components, counts) if m > 0]
        return np.concatenate(parts)[rng.permutation(draws)]

    def logpdf(self, x: np.ndarray) -> np.ndarray:
        """The mixture's log density at rows ``x``."""
        return logsumexp([np.log(w) + c.logpdf(x) for c, w in zip(self.components, self.weights)], axis=0)

    def widened(self, component) -> "_Mixture":
        """Half ``component``, half this mixture (the defensive part keeps what earlier proposals covered)."""
        return _Mixture([component, *self.components], [0.5, *(0.5 * self.weights)])


def _smoothed(raw: np.ndarray):
    """PSIS of raw log weights (non-finite ones weigh 0): (normalised smoothed log weights, Pareto k, effective draws),
    or None where no weight is finite."""
    finite = np.isfinite(raw)
    if not finite.any():
        return None
    smoothed, k = az.psislw(np.where(finite, raw, raw[finite].min() - 50.0), reff=1.0)
    smoothed = np.where(finite, smoothed, -np.inf)
    smoothed -= logsumexp(smoothed)
    return smoothed, float(k), float(1.0 / np.sum(np.exp(2 * smoothed)))


def _draw(proposal, log_density, draws, rng):
    x = proposal.rvs(draws, rng)
    log_p = log_density(x)
    raw = log_p - proposal.logpdf(x)
    return x, log_p, np.where(np.isfinite(raw), raw, -np.inf)


def _topped_up(proposal, log_density, drawn: tuple, weights, rng, draws: int, width_draws: float):
    """``drawn`` ((x, log_p, raw) from ``proposal``, ``weights`` its ``_smoothed``) with ``draws`` more at a time while
    its weights are trusted by Pareto k but short of the effective draws wanted, up to ``MAX_DRAWS`` in all:
    ``MIN_EFFECTIVE_DRAWS``, and ``width_draws`` where the walkers will compare SDs (k above ``BOUNDED_K``). Returns
    (x, log_p, raw, weights)."""
    x, log_p, raw = drawn
    while weights is not None and weights[1] <= PARETO_K_LIMIT and len(raw) + draws <= MAX_DRAWS:
        wanted = max(MIN_EFFECTIVE_DRAWS, width_draws if weights[1] > BOUNDED_K else 0.0)
        if weights[2] >= wanted:
            break
        more = _draw(proposal, log_density, draws, rng)
        x, log_p, raw = (np.concatenate([a, b]) for a, b in zip((x, log_p, raw), more))
        weights = _smoothed(raw)
    return x, log_p, raw, weights


def mode_and_precision(log_prob_z, z0: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The mode of the batched log density ``log_prob_z`` nearest ``z0`` and minus its Hessian there (central
    differences, each step half the axis's own width from a first pass with steps of 1e-2); None where the density
    or the Hessian is not finite there."""
    mode = _polish_mode(log_prob_z, z0)
    if not np.isfinite(log_prob_z(mode[None, :])[0]):
        return None
    curvature = -_hessian(log_prob_z, mode, np.full(mode.size, 1e-2)).diagonal()
    usable = np.isfinite(curvature) & (curvature > 0)
    scale = np.ones(mode.size)
    scale[usable] = 1.0 / np.sqrt(curvature[usable])
    precision = -_hessian(log_prob_z, mode, np.clip(0.5 * scale, 1e-5, 1.0))
    return (mode, precision) if np.all(np.isfinite(precision)) else None


def laplace_importance(posterior: Posterior, centre, rng: np.random.Generator, draws: int = 2000,
                       df: float = PROPOSAL_DF, adapt: bool = True, width_draws: float = 0.0) -> ImportanceSample | None:
    """Importance draws near the posterior, started from ``centre`` (an optimum in the declared parameters): a
    Student-t at the mode in the logit-CDF space with the Laplace covariance; where its weights are not reliable
    (and ``adapt``), an adapted t mixture in the declared parameters (the module's steps 3-4), returned where the first is not reliable, even if it is not either. None where the mode's Hessian is
    not negative definite or the log posterior is not finite there. The caller checks ``reliable``. With
    ``width_draws`` (the caller's walkers will compare SDs: ``WIDTH_EFFECTIVE_DRAWS``) a proposal trusted by Pareto k
    but short of 400 effective draws, or of ``width_draws`` where its k is above ``BOUNDED_K``, is drawn from again,
    ``draws`` at a time."""
    space = SamplingSpace(posterior.priors)
    log_prob_z = space.log_prob(posterior)
    found = mode_and_precision(log_prob_z, space.to_z(np.asarray(centre, float))[0])
    if found is None:
        return None
    mode, precision = found
    try:
        covariance = np.linalg.inv(precision)
        covariance = 0.5 * (covariance + covariance.T)
        proposal = _Mixture([multivariate_t(loc=mode, shape=covariance, df=df)], [1.0])
    except (np.linalg.LinAlgError, ValueError):  # not negative definite: no Gaussian approximation here
        return None
    drawn = _draw(proposal, log_prob_z, draws, rng)
    z, log_p, raw, weights = (*drawn, _smoothed(drawn[2]))
    if width_draws:
        z, log_p, raw, weights = _topped_up(proposal, log_prob_z, drawn, weights, rng, draws, width_draws)
    if weights is None:
        return None
    theta_mode = space.to_theta(mode[None, :])[0]
    sample = ImportanceSample(theta=space.to_theta(z), log_weights=weights[0], raw_log_weights=raw,
                              log_prob=space.log_posterior_theta(z, log_p), pareto_k=weights[1],
                              effective_draws=weights[2], mode=theta_mode,
                              proposal=f"multivariate t ({df:g} degrees of freedom) at the mode in the logit-CDF space, "
                                       "Laplace covariance")
    laplace_sd = np.sqrt(np.diag(covariance))
    sample.width_ratio = _width_ratio(space, sample, laplace_sd)
    if sample.reliable or not adapt:
        return sample
    adapted = _adapted_in_theta(posterior, space, mode, theta_mode, covariance, rng, draws, df, width_draws)
    if adapted is not None:
        adapted.width_ratio = _width_ratio(space, adapted, laplace_sd)
    return sample if adapted is None else adapted  # where neither is reliable, the last attempt (for the caller's message)


def _width_ratio(space: SamplingSpace, sample: ImportanceSample, laplace_sd: np.ndarray) -> float:
    """The smallest, over coordinates, of the weighted draws' SD in the sampling space over the Laplace SD there."""
    z = space.to_z(sample.theta)
    keep = np.all(np.isfinite(z), axis=1) & np.isfinite(sample.log_weights)
    if not keep.any():
        return 0.0
    return float(np.min(weighted_sd(z[keep], sample.log_weights[keep]) / laplace_sd))


def _adapted_in_theta(posterior, space, mode, theta_mode, covariance, rng, draws, df,
                      width_draws: float = 0.0) -> ImportanceSample | None:
    """The declared-parameter proposal (module step 4): the z-space Laplace covariance carried to theta by the
    delta method, then ``ADAPTATIONS`` moment-matching steps, each a t mixed half and half with what came before."""
    eps = 1e-6
    jacobian = (space.to_theta((mode + eps)[None, :])[0] - space.to_theta((mode - eps)[None, :])[0]) / (2 * eps)
    try:
        proposal = _Mixture([multivariate_t(loc=theta_mode, shape=covariance * np.outer(jacobian, jacobian), df=df)], [1.0])
    except (np.linalg.LinAlgError, ValueError):
        return None
    log_density = posterior.log_prob
    for step in range(ADAPTATIONS + 1):
        drawn = _draw(proposal, log_density, draws, rng)
        theta, log_p, raw = drawn
        weights = _smoothed(raw)
        if weights is None:
            return None
        if _trusted(weights[1], weights[2]) or step == ADAPTATIONS:
            # the last proposal, or the first trusted one, drawn from again while short of the effective draws wanted
            theta, log_p, raw, weights = _topped_up(proposal, log_density, drawn, weights, rng, draws, width_draws)
            break
        w = np.exp(weights[0])
        mean = w @ theta
        spread = (w[:, None] * (theta - mean)).T @ (theta - mean)
        try:
            proposal = proposal.widened(multivariate_t(loc=mean, shape=0.5 * (spread + spread.T), df=df))
        except (np.linalg.LinAlgError, ValueError):  # the weights sit on fewer draws than dimensions
            return None
    if weights is None:
        return None
    return ImportanceSample(theta=theta, log_weights=weights[0], raw_log_weights=raw, log_prob=log_p,
                            pareto_k=weights[1], effective_draws=weights[2], mode=theta_mode,
                            proposal=f"mixture of {len(proposal.components)} multivariate t's ({df:g} degrees of freedom) "
                                     "in the declared parameters, adapted to the weighted draws (a parameter at a bound)")


def importance_loo(log_likelihood: np.ndarray, raw_log_weights: np.ndarray, labels) -> dict:
    """PSIS-LOO from importance draws of an approximate posterior: ``log_likelihood`` (S, M) pointwise at the
    draws, ``raw_log_weights`` (S,) log p(theta | y) - log q(theta). The same fields as ``diagnostics.loo``; p_loo
    against the weighted mean log predictive density."""
    finite = np.isfinite(raw_log_weights)
    ll, raw = log_likelihood[finite], raw_log_weights[finite]
    smoothed, k = psis_log_weights((raw[:, None] - ll).T, reff=1.0)  # (M, S): ArviZ's psislw, vectorised
    smoothed += ll.T
    pointwise = logsumexp_rows(smoothed)
    failed = ~np.isfinite(pointwise)
    weights = raw - logsumexp(raw)
    lpd = logsumexp_rows(weights[None, :] + ll.T)  # the weighted in-sample log predictive density
    if failed.any():  # as diagnostics.loo: the in-sample density, flagged unreliable
        pointwise[failed] = lpd[failed]
        k[failed] = np.inf
    return loo_fields(pointwise, k, lpd.sum() - pointwise.sum(), labels)
