"""The posterior with its noise levels profiled out (infer.profiled): what the start-point searches climb.

Each profiled level must be the RMS of its channels' residuals (computed here with numpy from the model's own
prediction, not through the likelihood), clipped to its prior's bounds; the profiled log-likelihood must equal
the full one at the completed parameter vector, and no other level may do better there."""

import numpy as np
import pytest

from spacepol.infer.posterior import Posterior
from spacepol.infer.profiled import ProfiledPosterior
from spacepol.priors import Fixed, Uniform
from spacepol.io.measurements import Dataset
from spacepol.physics import Model


def _dataset(n=30, seed=0):
    rng = np.random.default_rng(seed)
    ti, tr = np.full(n, 40.0), np.linspace(5, 75, n)
    model = Model.from_string("paper")
    data = Dataset(ti, tr, np.full(n, 180.0))
    truth = model.evaluate({"n": 1.5, "k": 0.1}, data.geometry)
    data.dop = truth.dop + 0.01 * rng.standard_normal(n)
    data.brdf = truth.brdf * np.exp(0.05 * rng.standard_normal(n))
    return data, model


def test_each_level_is_the_rms_of_its_residuals_and_the_full_likelihood_agrees():
    data, model = _dataset()
    post = Posterior.build(data, model, noise_floor=False)
    profiled = ProfiledPosterior.of(post)
    assert [name for name, _, _ in profiled.levels] == ["sigma_dop", "sigma_brdf_rel"]
    assert "sigma_dop" not in profiled.priors.names and profiled.ndim == post.ndim - 2
    theta = profiled.priors.sample(np.random.default_rng(1), 8)
    full = profiled.complete(theta)
    # independently: the residual RMS per channel from the model's prediction
    mu = model.evaluate(profiled.model_params(theta), data.geometry)
    bounds = dict((name, (lo, hi)) for name, lo, hi in profiled.levels)
    dop_rms = np.sqrt(np.mean((data.dop - mu.dop) ** 2, axis=-1))
    brdf_rms = np.sqrt(np.mean((np.log(data.brdf) - np.log(mu.brdf)) ** 2, axis=-1))
    column = {n: j for j, n in enumerate(post.priors.names)}
    np.testing.assert_allclose(full[:, column["sigma_dop"]], np.clip(dop_rms, *bounds["sigma_dop"]), rtol=1e-10)
    np.testing.assert_allclose(full[:, column["sigma_brdf_rel"]], np.clip(brdf_rms, *bounds["sigma_brdf_rel"]), rtol=1e-10)
    np.testing.assert_allclose(profiled.log_likelihood(theta), post.log_likelihood(full), rtol=1e-12)
    # the profiled levels are the maximum: any other level lowers the full log-likelihood
    for name in ("sigma_dop", "sigma_brdf_rel"):
        for factor in (0.97, 1.03):
            moved = full.copy()
            moved[:, column[name]] *= factor
            inside = np.all((moved >= post.priors.bounds[:, 0]) & (moved <= post.priors.bounds[:, 1]), axis=1)
            assert np.all(post.log_likelihood(moved)[inside] < post.log_likelihood(full)[inside])


def test_a_level_is_clipped_to_its_prior_and_fixed_or_given_noise_is_not_profiled():
    data, model = _dataset()
    post = Posterior.build(data, model, {"sigma_dop": Uniform(0.2, 0.3)}, noise_floor=False)  # far above the residuals
    profiled = ProfiledPosterior.of(post)
    truth = {p.name: p.default for p in model.parameters} | {"n": 1.5, "k": 0.1}  # as _dataset rendered it: RMS ~0.01
    theta = np.array([[truth[name] for name in profiled.priors.names]])
    assert profiled.complete(theta)[0, post.priors.names.index("sigma_dop")] == 0.2
    fixed = ProfiledPosterior.of(Posterior.build(data, model, {"sigma_dop": Fixed(0.01)}, noise_floor=False))
    assert [name for name, _, _ in fixed.levels] == ["sigma_brdf_rel"]
    data.dop_err, data.brdf_err = np.full(len(data), 0.01), np.full(len(data), 0.05 * data.brdf)
    assert ProfiledPosterior.of(Posterior.build(data, model)) is None  # the file's errors: nothing to profile
    assert ProfiledPosterior.of(Posterior.build(_dataset()[0], model, robust=True)) is None  # Student-t: no closed form


def test_the_profiled_search_ends_on_the_full_posterior_at_least_as_high_as_its_start():
    from spacepol.infer.optimum import find_optimum_profiled, polish_posterior

    data, model = _dataset()
    post = Posterior.build(data, model, noise_floor=False)
    value, theta = find_optimum_profiled(post, np.random.default_rng(0), evaluations=1500)
    assert value == pytest.approx(float(post.log_prob(theta[None, :])[0]), rel=1e-12)
    assert polish_posterior(post, theta)[0] == pytest.approx(value, abs=1e-3)  # a local maximum already
    names = dict(zip(post.priors.names, theta))
    assert names["n"] == pytest.approx(1.5, abs=0.1) and 0.005 < names["sigma_dop"] < 0.02


@pytest.mark.parametrize("profile", [False, True])
def test_a_branch_is_the_posterior_with_its_parameters_held_and_compiles_nothing_new(profile):
    """An effect's branch (k = 0 of ``specular``) equals the posterior built with k fixed by its prior, evaluated
    through the parent's compiled program (held values as columns, not as compiled-in constants)."""
    from spacepol.infer.optimum import _branches
    from spacepol.infer.posterior import PinnedPosterior

    data, model = _dataset()
    post = Posterior.build(data, model, noise_floor=False)
    parent = ProfiledPosterior.of(post) if profile else post
    (pinned, branch), = list(_branches(parent))
    assert pinned == {"k": 0.0} and isinstance(branch, PinnedPosterior) and "k" not in branch.priors.names
    theta = branch.priors.sample(np.random.default_rng(2), 16)
    parent.log_prob(branch.expand(theta))  # the parent's program, compiled
    programs = set(post.likelihood._jitted)
    value = branch.log_prob(theta)
    assert set(post.likelihood._jitted) == programs
    fixed = type(parent)(parent.likelihood, branch.priors, parent.levels, parent.full) if profile else \
        Posterior(parent.likelihood, branch.priors)  # k compiled in as a constant: the reference
    np.testing.assert_allclose(value, fixed.log_prob(theta), rtol=1e-12)
    moved = branch.expand(theta)
    moved[:, parent.priors.names.index("k")] = 0.3  # negative control: another k is another posterior
    assert np.all(np.abs(parent.log_prob(moved) - value) > 1e-6)


def test_the_search_on_every_other_row_ends_where_the_search_on_all_does():
    """``find_optimum_on_every``: the global search on a subset of the rows (the same priors: ``Posterior.on_rows``
    keeps the measured noise floors), polished on all rows, reaches the full search's maximum on a set whose
    optimum the subset pins; the subset posterior itself is the full one's rows only (the control)."""
    from spacepol.infer.optimum import find_optimum_on_every, find_optimum_profiled

    data, model = _dataset()
    post = Posterior.build(data, model, noise_floor=False)
    half = post.on_rows(np.arange(0, len(data), 2))
    assert half.priors is post.priors and len(half.likelihood.data) == (len(data) + 1) // 2
    theta = post.priors.rescale(np.random.default_rng(1).random((4, post.ndim)))
    assert not np.allclose(half.log_prob(theta), post.log_prob(theta))
    full, _ = find_optimum_profiled(post, np.random.default_rng(0), evaluations=1500)
    value, best = find_optimum_on_every(post, 2, np.random.default_rng(0), evaluations=1500)
    assert value == pytest.approx(float(post.log_prob(best[None, :])[0]), rel=1e-12)
    assert value == pytest.approx(full, abs=0.05), f"every other row {value:.3f}, all rows {full:.3f}"
