"""A posterior from its mode: a Gaussian (Laplace) approximation, corrected by Pareto-smoothed importance sampling.

Where a model is compared with its neighbours (diagnose's refits), the question is each one's predictive
accuracy (ELPD-LOO), and on thousands of numbers the posterior of a dozen parameters is close to a Gaussian
around its mode. So:

1. the mode in the sampling space z (``sampling_space``: the logit of each prior's CDF, where no bound is
   left and the declared priors hold exactly), polished by L-BFGS from an optimum already found;
2. the Hessian there by central differences of the batched log posterior (steps of half a posterior SD,
   from a first pass on the diagonal);
3. draws from a multivariate Student-t (5 degrees of freedom: tails heavier than the Gaussian's, so the
   importance ratios stay bounded where the posterior is skewed) with that mode and covariance. On PTFE's
   ``paper`` posterior (rho_d and a noise level piled at bounds) three seeds gave Pareto k 0.43-0.61 with 5
   degrees of freedom, 0.66-0.78 with 7, 0.54-0.74 with 15;
4. where a parameter piles at a bound of its prior (a dielectric's k at 0), its marginal in z has an exponential
   tail towards the bound that no t at the mode matches, and curved correlations with the parameters it trades
   against (k with k_s). Then the draws are made in the declared parameters instead, where such a posterior is
   a Gaussian cut by the bound (draws outside the prior weigh 0): a t from the Laplace covariance carried over
   by the delta method, adapted (up to eight times, until the weights are trusted) to the weighted draws' mean and
   covariance, each adapted t mixed half and half with the proposals before it; where the last one's Pareto k is
   <= 0.7 but its effective draws are short of 400, more draws from it (up to 10,000 in all: a volume-scattering
   PTFE posterior, two phase-matrix parameters near a bound, needed 4,000-6,000; with three adaptations and 2,000
   draws it gave k 0.55-0.77 and 80-110 effective draws, and emcee took ~90 s instead of ~2 s)
   (population Monte Carlo with a defensive mixture: Cappe et al.,
   J. Comput. Graph. Stat. 13, 907 (2004); Hesterberg, Technometrics 37, 185 (1995)). On the validation
   suite's null set (k = 0 at the bound; 3 seeds) the t in z gave Pareto k 0.74-1.03 for ``paper`` and four
   candidates; the adapted mixture 0.27-0.52 for ``+polarized_diffuse``, ``+lambertian`` and ``+extinction``,
   0.19-0.70 for ``+dop_bias`` and 0.54-0.94 for ``paper`` itself (8 seeds; refused in half: emcee then).
   ``tests/test_laplace.py`` checks it against emcee;
5. importance weights log p | y - log q, Pareto-smoothed (PSIS, Vehtari et al., JMLR 25(72), 2024). Their
   Pareto k says whether the approximation can be trusted at all (Yao et al., "Yes, but did it work?",
   ICML 2018): accepted only where k <= 0.7 and the weights' effective sample size is at least 400 (emcee's
   ESS target; ``ImportanceSample.reliable``);
6. and only where the weights have not collapsed onto the mode: Pareto k sees the tail of the weights the draws
   reached, not posterior mass the proposal never reached. On a curved ridge (PTFE's ``paper+lambertian+oxide_layer``
   and its ``shadowing -> smith`` alternative at 0.633 um: n, k and the film thickness trade along it) the t at the
   mode lands mostly off the ridge, a few draws on it take all the weight, and the adapted proposals, matched to
   those few, shrink onto the mode: trusted by k (0.46-0.55) with SDs of n and k half the Laplace's in z, and half
   of what emcee shows (n 2.08 +- 0.41 from walkers started inside the importance draws, which spread out). On
   posteriors where the approximation holds (``paper``, ``paper+lambertian``, three seeds each) every coordinate's
   weighted SD in z was 0.97-1.26 of the Laplace SD; on the collapsed ones n, k and the thickness were at 0.46-0.53.
   So a coordinate narrower than ``MIN_WIDTH_RATIO`` (0.75) x its Laplace SD refuses the approximation (a posterior
   flatter-topped than a Gaussian is refused too: emcee then, slower but right).
Otherwise the caller samples with emcee (``inversion.invert_laplace`` returns None).

PSIS-LOO from such draws takes the approximation into account (Magnusson et al., "Bayesian leave-one-out
cross-validation for large data", ICML 2019; ``loo_approximate_posterior`` in the R package loo): observation
i's log ratios are log p(z_s | y) - log q(z_s) - log p(y_i | z_s), smoothed per observation (``importance_loo``).
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
from .spread_check import weighted_sd

MIN_EFFECTIVE_DRAWS = 400  # as emcee's ESS target
PROPOSAL_DF = 5.0
ADAPTATIONS = 8  # at most this many moment-matching steps of the declared-parameter proposal
# the weighted draws' SD of each coordinate in the sampling space z, over the Laplace SD there, below which the weights
# are taken to have collapsed onto the mode (see the module's step 6)
MIN_WIDTH_RATIO = 0.75
MAX_DRAWS = 10000  # the last proposal, trusted (Pareto k <= 0.7) but short of 400 effective draws, is drawn from up to this many


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


def laplace_importance(posterior: Posterior, centre, rng: np.random.Generator, draws: int = 2000,
                       df: float = PROPOSAL_DF, adapt: bool = True) -> ImportanceSample | None:
    """Importance draws near the posterior, started from ``centre`` (an optimum in the declared parameters): a
    Student-t at the mode in the logit-CDF space with the Laplace covariance; where its weights are not reliable
    (and ``adapt``), an adapted t mixture in the declared parameters (the module's steps 3-4), returned where the first is not reliable, even if it is not either. None where the mode's Hessian is
    not negative definite or the log posterior is not finite there. The caller checks ``reliable``."""
    space = SamplingSpace(posterior.priors)
    log_prob_z = space.log_prob(posterior)
    mode = _polish_mode(log_prob_z, space.to_z(np.asarray(centre, float))[0])
    if not np.isfinite(log_prob_z(mode[None, :])[0]):
        return None
    curvature = -_hessian(log_prob_z, mode, np.full(mode.size, 1e-2)).diagonal()
    usable = np.isfinite(curvature) & (curvature > 0)
    scale = np.ones(mode.size)
    scale[usable] = 1.0 / np.sqrt(curvature[usable])
    precision = -_hessian(log_prob_z, mode, np.clip(0.5 * scale, 1e-5, 1.0))
    if not np.all(np.isfinite(precision)):
        return None
    try:
        covariance = np.linalg.inv(precision)
        covariance = 0.5 * (covariance + covariance.T)
        proposal = _Mixture([multivariate_t(loc=mode, shape=covariance, df=df)], [1.0])
    except (np.linalg.LinAlgError, ValueError):  # not negative definite: no Gaussian approximation here
        return None
    z, log_p, raw = _draw(proposal, log_prob_z, draws, rng)
    weights = _smoothed(raw)
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
    adapted = _adapted_in_theta(posterior, space, mode, theta_mode, covariance, rng, draws, df)
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


def _adapted_in_theta(posterior, space, mode, theta_mode, covariance, rng, draws, df) -> ImportanceSample | None:
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
        theta, log_p, raw = _draw(proposal, log_density, draws, rng)
        weights = _smoothed(raw)
        if weights is None:
            return None
        if _trusted(weights[1], weights[2]):
            break
        if step == ADAPTATIONS:
            # the last proposal, drawn from again while its weights are trusted but short of 400 effective draws
            while (weights is not None and weights[1] <= PARETO_K_LIMIT and weights[2] < MIN_EFFECTIVE_DRAWS
                   and len(raw) + draws <= MAX_DRAWS):
                more = _draw(proposal, log_density, draws, rng)
                theta, log_p, raw = (np.concatenate([a, b]) for a, b in zip((theta, log_p, raw), more))
                weights = _smoothed(raw)
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
