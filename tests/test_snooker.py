"""The snooker move keeps the posterior: on a correlated 10-dimensional Gaussian, -2 log p of the chain's draws
has mean D (chi^2 with D degrees of freedom); emcee 3.1.6's own snooker (the negative control) does not."""

import emcee
import numpy as np

from spacepol.infer.engines.snooker import DESnookerMove

D = 10


def _chi2_mean(move, seed=0):
    """(mean of -2 log p over the kept draws, its Monte-Carlo standard error from the series' autocorrelation)."""
    rng = np.random.default_rng(seed)
    a = rng.standard_normal((D, D))
    covariance = a @ a.T + D * np.eye(D)
    precision = np.linalg.inv(covariance)

    def log_prob(x):
        return -0.5 * np.einsum("ij,jk,ik->i", x, precision, x)

    sampler = emcee.EnsembleSampler(40, D, log_prob, vectorize=True, moves=[(move, 1.0)])
    sampler.random_state = np.random.RandomState(seed).get_state()
    sampler.run_mcmc(rng.multivariate_normal(np.zeros(D), covariance, 40), 2500, progress=False)
    chi2 = -2 * sampler.get_log_prob(discard=500)  # (steps, walkers)
    tau = emcee.autocorr.integrated_time(chi2.mean(axis=1, keepdims=True), quiet=True)[0]
    se = np.sqrt(2 * D * tau / chi2.size)
    return float(chi2.mean()), float(se)


def test_the_snooker_move_keeps_a_gaussian_posterior():
    mean, se = _chi2_mean(DESnookerMove())
    assert abs(mean - D) < 4 * se, (mean, se)


def test_emcees_own_snooker_move_is_caught_by_the_same_check():
    mean, se = _chi2_mean(emcee.moves.DESnookerMove())
    assert mean < D - 4 * se, (mean, se)  # too narrow
