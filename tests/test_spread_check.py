"""The Laplace-IS gate's last check (``infer.spread_check``): emcee walkers started inside importance draws that
Pareto k trusts spread beyond them where the draws are narrower than the posterior (a metal's curved n-k band, the
DOP-only ridge), and stay as wide as they are where the draws are right (the near-Gaussian control). Where the gate
refuses, the ``laplace`` engine samples with emcee and says so."""

import numpy as np
import pytest

import spacepol
from ridges import METAL, band_data, band_posterior
from spacepol.infer.inversion import laplace_fit
from spacepol.infer.laplace import WIDTH_EFFECTIVE_DRAWS, laplace_importance
from spacepol.infer.optimum import find_optimum
from spacepol.infer.posterior import Posterior
from spacepol.infer.spread_check import BOUNDED_K, EARLY_LOOKS, MAX_SD_GROWTH, STEPS, spread_check
from spacepol.io import read_measurements
from spacepol.paths import bundled
from spacepol.physics import Model


@pytest.fixture(scope="module")
def metal_band():
    """DOP and a BRDF with 100 % noise of the paper's aluminium: n and k trade along a curved band."""
    post = band_posterior(METAL, brdf_noise=1.0)
    _, centre = find_optimum(post, np.random.default_rng(0))
    return post, centre


def test_draws_trusted_by_pareto_k_on_a_curved_band_are_refused_by_the_walkers_spread(metal_band):
    """Pareto k and the effective draws trust these proposals (the old gate), whose SDs of n are 0.71-0.76 of
    emcee's; the walkers spread beyond them in n. Over six seeds of proposal and walkers the pooled growth of n's SD
    lies many Monte-Carlo SEs above the limit, and at least five of the six are refused (one seed's growth is a
    noisy estimate, 2-6 SEs above the limit: the count tolerates one at the limit, so no float rounding of one CPU
    decides the test); the engine's refusal names n."""
    post, centre = metal_band
    growths, errors = [], []
    for seed in range(1, 7):
        # as the engine draws them: topped up to ``WIDTH_EFFECTIVE_DRAWS`` where the walkers compare SDs
        sample = laplace_importance(post, centre, np.random.default_rng(seed), width_draws=WIDTH_EFFECTIVE_DRAWS)
        assert sample is not None and sample.reliable, "the control: the weights' own checks trust these draws"
        assert sample.pareto_k > BOUNDED_K + 0.2, f"k {sample.pareto_k:.2f}: the walkers run on this band"
        check = spread_check(post, sample, np.random.default_rng(seed).spawn(1)[0])
        j = check.names.index("n")
        growths.append(check.ratios[j])
        errors.append(check.standard_error[j])
    growths, errors = np.array(growths), np.array(errors)
    pooled, pooled_se = growths.mean(), np.sqrt(np.sum(errors**2)) / len(errors)
    margin = (pooled - MAX_SD_GROWTH) / pooled_se
    summary = f"n's SD grew {np.round(growths, 3)}x (SE {np.round(errors, 3)}), pooled {pooled:.3f}: {margin:.1f} SE above {MAX_SD_GROWTH}"
    assert margin > 5, summary
    assert np.sum(growths > MAX_SD_GROWTH) >= 5, summary
    result, why = laplace_fit(post, centre, seed=int(np.argmax(growths)) + 1)
    assert result is None and "spread beyond them" in why and "n " in why, why


@pytest.fixture(scope="module")
def paper_set():
    """The 84-point paper set's posterior (near-Gaussian) and its optimum."""
    post = Posterior.build(read_measurements(bundled("synthetic", "hidden_effect.csv")), Model.from_string("paper"))
    _, centre = find_optimum(post, np.random.default_rng(0))
    return post, centre


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_right_draws_keep_their_width_under_the_walkers(paper_set, seed):
    """The negative control: on the 84-point paper set (near-Gaussian; Laplace-IS agrees with emcee there,
    ``test_laplace``) no parameter's SD grows beyond the limit; the margin is printed. (The engine runs no walkers
    here, their weights being bounded: ``test_bounded_weights_need_no_walkers``.)"""
    post, centre = paper_set
    sample = laplace_importance(post, centre, np.random.default_rng(seed))
    check = spread_check(post, sample, np.random.default_rng(seed).spawn(1)[0], skip_bounded=False)
    name, widest = check.widest
    assert widest < MAX_SD_GROWTH - 0.03, f"{name}'s SD grew {widest:.3f}x (limit {MAX_SD_GROWTH}): {check.to_json()}"
    assert check.refusal == "" and check.steps == STEPS  # no early look refuses right draws: the whole run decides


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_bounded_weights_need_no_walkers(paper_set, seed):
    """Where the weights' Pareto k is at most ``BOUNDED_K`` (their tail bounded) the walkers are not run, and the
    fit says so; on the same draws the walkers, run anyway, keep the width (the control above): skipping them
    changes the cost, not the answer. The margin of k below the bound is printed."""
    post, centre = paper_set
    sample = laplace_importance(post, centre, np.random.default_rng(seed))
    margin = BOUNDED_K - sample.pareto_k
    assert margin > 0.05, f"Pareto k {sample.pareto_k:.3f}: {margin:.3f} below {BOUNDED_K}"
    check = spread_check(post, sample, np.random.default_rng(seed).spawn(1)[0])
    assert check.steps == 0 and check.refusal == "" and check.widest == (None, None)
    assert check.to_json()["walkers_run"] is False and "bounded" in check.to_json()["why"]
    result, why = laplace_fit(post, centre, seed=seed)
    assert result is not None, why
    assert result.summary.diagnostics["sd_growth_max"] is None


def test_draws_are_topped_up_only_where_the_walkers_compare_sds(metal_band, paper_set):
    """Where the walkers will run (Pareto k above ``BOUNDED_K``: the metal band) the engine's proposal is drawn from
    again, 2,000 at a time, until ``WIDTH_EFFECTIVE_DRAWS`` effective draws or ``MAX_DRAWS``; the first 2,000 are the
    draws of a run without it. Where the weights are bounded (the paper set) nothing more is drawn. Control: without
    ``width_draws`` the metal band's sample stays at 2,000 draws, short of the target."""
    from spacepol.infer.laplace import MAX_DRAWS

    post, centre = metal_band
    plain = laplace_importance(post, centre, np.random.default_rng(3))
    topped = laplace_importance(post, centre, np.random.default_rng(3), width_draws=WIDTH_EFFECTIVE_DRAWS)
    assert len(plain.theta) == 2000 and plain.effective_draws < WIDTH_EFFECTIVE_DRAWS, plain.effective_draws
    assert plain.pareto_k > BOUNDED_K + 0.2 and len(topped.theta) % 2000 == 0 and len(topped.theta) > 2000
    assert topped.effective_draws >= WIDTH_EFFECTIVE_DRAWS or len(topped.theta) + 2000 > MAX_DRAWS, topped.effective_draws
    np.testing.assert_array_equal(topped.theta[:2000], plain.theta)
    post, centre = paper_set
    bounded = laplace_importance(post, centre, np.random.default_rng(0), width_draws=WIDTH_EFFECTIVE_DRAWS)
    assert bounded.pareto_k <= BOUNDED_K and len(bounded.theta) == 2000, (bounded.pareto_k, len(bounded.theta))


def test_the_dop_ridges_trusted_draws_are_refused_by_the_walkers_spread_too():
    """The DOP-only ridge (refused before any draw by ``scale_ridge``): its proposals that Pareto k trusts would be
    refused by the spread as well, with a growth in n far above the limit."""
    post = band_posterior(METAL)
    _, centre = find_optimum(post, np.random.default_rng(0))
    sample = laplace_importance(post, centre, np.random.default_rng(6))
    assert sample.reliable and sample.pareto_k > BOUNDED_K + 0.2, sample.pareto_k
    check = spread_check(post, sample, np.random.default_rng(6).spawn(1)[0])
    growth = dict(zip(check.names, check.ratios))
    assert growth["n"] > MAX_SD_GROWTH + 0.2, growth
    # refused part-way: the walkers had spread far beyond the draws at one of the early looks
    assert check.steps in EARLY_LOOKS and check.clearly_refused and check.refusal, (check.steps, growth)


def test_the_laplace_engine_falls_back_to_emcee_and_says_so(tmp_path):
    """Where the gate refuses, ``engine="laplace"`` samples with emcee: the summary names what ran and why."""
    result = spacepol.invert(band_data(METAL, brdf_noise=1.0), "paper", engine="laplace", seed=1, out=tmp_path / "run")
    assert result.summary.diagnostics["engine"] == result.summary.engine == "emcee"
    assert "spread beyond them" in result.summary.laplace_refused
    saved = spacepol.Result.load(tmp_path / "run")
    assert saved.summary.engine == "emcee" and saved.summary.laplace_refused
    assert "Laplace approximation was refused" in (tmp_path / "run" / "report.html").read_text()
    # the fallback keeps its chain in the run folder, as emcee does: the same call again reads it instead of sampling
    assert (tmp_path / "run" / "chain.h5").exists()
    again = spacepol.invert(band_data(METAL, brdf_noise=1.0), "paper", engine="laplace", seed=1, out=tmp_path / "run")
    np.testing.assert_array_equal(again.draws.flat_samples(), result.draws.flat_samples())
