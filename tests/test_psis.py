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
