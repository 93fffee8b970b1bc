"""infer.elpd_settled: a chain run for its ELPD-LOO alone stops where its two halves agree, and only there."""

from types import SimpleNamespace

import numpy as np

from spacepol.infer.elpd_settled import elpd_loo_of, settled


def _gaussian_mean_posterior(y):
    """A stub posterior: y_i ~ N(mu, 1), theta = (mu,); what ``settled`` reads of a Posterior."""
    def pointwise(theta):
        return -0.5 * (y[None, :] - theta[:, :1]) ** 2 - 0.5 * np.log(2 * np.pi)

    return SimpleNamespace(log_prob_pointwise=pointwise, likelihood=SimpleNamespace(batch_sets=256))


def test_elpd_loo_of_draws_matches_the_exact_leave_one_out_predictive():
    """For a Gaussian mean with a flat prior the LOO predictive of y_i is N(mean of the others, 1 + 1/(n-1)):
    ELPD-LOO of 4,000 exact posterior draws (as 125 steps of 32 walkers) equals it within Monte-Carlo error (0.5 on
    n = 200), with no observation's Pareto k above 0.7."""
    rng = np.random.default_rng(0)
    y = rng.normal(0.3, 1.0, 200)
    n = len(y)
    chain = rng.normal(y.mean(), 1 / np.sqrt(n), (125, 32, 1))
    others = (y.sum() - y) / (n - 1)
    var = 1 + 1 / (n - 1)
    exact = float(np.sum(-0.5 * (y - others) ** 2 / var - 0.5 * np.log(2 * np.pi * var)))
    elpd, bad = elpd_loo_of(_gaussian_mean_posterior(y), chain, draws=4000)
    assert abs(elpd - exact) < 0.5 and bad == 0.0


def test_halves_from_one_posterior_settle_and_halves_from_two_modes_do_not():
    """Walkers (steps, walkers, 1) drawn from the posterior in both halves: settled at the first check. Controls: the
    second half displaced by 0.3 (walkers gone to another mode; its ELPD-LOO ~ n x 0.045 = 9 lower): not settled;
    halves that agree but whose PSIS-LOO is unreliable for more than 1 % of the observations (every draw at the
    same few values: the importance ratios' tails are steps): not settled; nor before ``first_step``."""
    rng = np.random.default_rng(1)
    y = rng.normal(0.0, 1.0, 200)
    posterior = _gaussian_mean_posterior(y)
    chain = rng.normal(y.mean(), 1 / np.sqrt(len(y)), (1000, 32, 1))
    enough = settled(posterior)
    assert enough(2000, chain)
    step, first, second, bad = enough.checks[-1]
    assert step == 2000 and abs(first - second) <= 2.0 and bad <= 0.01
    moved = chain.copy()
    moved[500:] += 0.3
    assert not enough(2000, moved)
    assert abs(enough.checks[-1][1] - enough.checks[-1][2]) > 5
    stuck = np.where(rng.random(chain.shape) < 0.995, y.mean(), y.mean() + rng.normal(0, 0.3, chain.shape))
    assert not enough(2000, stuck) and enough.checks[-1][3] > 0.01, enough.checks[-1]
    assert not enough(1000, chain) and not enough(2500, chain)  # before the first check, between checks


def test_a_chain_stops_when_its_caller_has_enough_and_not_otherwise():
    """sample_emcee's ``enough``: the run ends at the first check where it says so, reported as stopped early
    (not capped); control: the same run without it goes on to its cap."""
    from spacepol.infer.engines.emcee_sampler import sample_emcee
    from spacepol.infer.posterior import Posterior
    from spacepol.physics import Model
    from test_sampler import synthetic

    data = synthetic("paper", {"n": 1.4, "k": 0.2, "sigma": 0.2, "ks": 0.5, "rho_d": 0.1})
    post = Posterior.build(data, Model.from_string("paper"))
    kwargs = dict(walkers=16, max_steps=1200, check_every=200, min_steps=10**9, progress=False, initial="prior")
    calls = []

    def enough(step, chain):
        calls.append((step, chain.shape))
        return step >= 600

    stopped = sample_emcee(post, np.random.default_rng(7), enough=enough, **{**kwargs, "min_steps": 400})
    assert stopped.info["steps"] == 600 and stopped.info["stopped_early"] and not stopped.info["capped"]
    assert [s for s, _ in calls] == [400, 600] and calls[-1][1][1:] == (16, post.ndim)
    full = sample_emcee(post, np.random.default_rng(7), **kwargs)
    assert full.info["steps"] == 1200 and not full.info["stopped_early"] and full.info["capped"]
