"""infer.psis: ArviZ's PSIS vectorised over observations gives ArviZ's numbers (its own per-row loop is the
independent reference), on rows that take every branch of the algorithm."""

import arviz as az
import numpy as np
import pytest

from spacepol.infer.psis import logsumexp_rows, psis_log_weights


def _ratios(rng, rows=300, draws=2000):
    """Log importance ratios of every kind: light and heavy tails (Pareto k from ~0 to > 1), a near-constant row,
    ties at the cutoff, a row under the underflow limit, and -inf entries."""
    scale = rng.uniform(0.05, 3.0, rows)[:, None]
    x = scale * rng.standard_normal((rows, draws))
    x[: rows // 4] = np.log(rng.pareto(rng.uniform(0.6, 4.0, rows // 4)[:, None], (rows // 4, draws)) + 1e-9)
    x[-1] = 0.0  # constant: every draw ties
    x[-2, :1500] = 0.0  # ties at the cutoff
    x[-3] = np.linspace(0, 1, draws)
    x[-3, :-3] = -1000.0  # the cutoff far below the underflow limit
    x[-4, ::7] = -np.inf
    return x


@pytest.mark.parametrize("draws", [2000, 8000, 20])
def test_the_vectorised_psis_is_arviz_psis(draws):
    rng = np.random.default_rng(1)
    x = _ratios(rng, draws=draws)
    ours, k = psis_log_weights(x)
    theirs, k_ref = az.psislw(x.copy(), reff=1.0)
    theirs, k_ref = np.asarray(theirs), np.asarray(k_ref)
    assert np.allclose(k, k_ref, rtol=1e-10, atol=1e-12, equal_nan=True)
    finite = np.isfinite(theirs)
    assert np.array_equal(finite, np.isfinite(ours))
    assert np.max(np.abs(ours[finite] - theirs[finite])) < 1e-10
    if draws > 100:  # the rows span the diagnostic's range
        assert k_ref.min() < 0.3 and np.nanmax(k_ref[np.isfinite(k_ref)]) > 0.7


def test_a_wrong_smoothing_is_caught():
    """Negative control: the comparison above fails for weights that are only normalised (no Pareto smoothing)."""
    x = _ratios(np.random.default_rng(1))
    theirs, _ = az.psislw(x.copy(), reff=1.0)
    plain = x - np.max(x, axis=1, keepdims=True)
    plain = plain - logsumexp_rows(plain)[:, None]
    finite = np.isfinite(np.asarray(theirs))
    assert np.max(np.abs(plain[finite] - np.asarray(theirs)[finite])) > 1e-3


def test_logsumexp_rows():
    from scipy.special import logsumexp

    x = np.random.default_rng(0).normal(scale=50, size=(7, 300))
    x[0] = -np.inf
    assert np.allclose(logsumexp_rows(x)[1:], logsumexp(x[1:], axis=1), rtol=1e-13)
    assert logsumexp_rows(x)[0] == -np.inf


def _mcmc_idata(rng, chains=8, draws=250, observations=400):
    """Several chains of autocorrelated draws (an AR(1) per chain, so the relative efficiency is well below 1) and
    a log-likelihood per observation whose spread over the draws ranges from narrow to heavy-tailed."""
    theta = np.zeros((chains, draws, 2))
    for t in range(1, draws):
        theta[:, t] = 0.9 * theta[:, t - 1] + np.sqrt(1 - 0.81) * rng.standard_normal((chains, 2))
    y = rng.standard_normal(observations) * 2.0
    spread = rng.uniform(0.2, 3.0, observations)
    mu = theta[..., :1] * spread + theta[..., 1:] * 0.3  # (chains, draws, observations)
    log_likelihood = -0.5 * (y - mu) ** 2
    return az.from_dict(posterior={"a": theta[..., 0], "b": theta[..., 1]}, log_likelihood={"y": log_likelihood},
                        dims={"y": ["obs_id"]}, coords={"obs_id": np.arange(observations)})


def test_mcmc_loo_is_arvizs_with_its_relative_efficiency():
    """``diagnostics.loo`` (the vectorised smoothing) against ``arviz.loo`` itself on several autocorrelated chains:
    pointwise ELPD, Pareto k and p_loo to 1e-9; the control, the same with the relative efficiency left at 1, differs."""
    import warnings

    from spacepol.infer.diagnostics import loo

    idata = _mcmc_idata(np.random.default_rng(3))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        theirs = az.loo(idata, pointwise=True, var_name="y")
    ours = loo(idata)
    assert np.max(np.abs(ours["pointwise"] - np.asarray(theirs.loo_i))) < 1e-9
    assert np.allclose(ours["pareto_k"], np.asarray(theirs.pareto_k), rtol=1e-9, atol=1e-12)
    assert abs(ours["p_loo"] - float(theirs.p_loo)) < 1e-8
    assert abs(ours["elpd_loo"] - float(theirs.elpd_loo)) < 1e-8
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        unit = az.loo(idata, pointwise=True, var_name="y", reff=1.0)
    assert np.max(np.abs(np.asarray(unit.pareto_k) - np.asarray(theirs.pareto_k))) > 1e-3  # reff matters here
