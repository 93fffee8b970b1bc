"""Priors as objects, prior files, and the likelihood's densities."""

import numpy as np
import pytest
from scipy import stats

from spacepol.errors import ParameterError
from spacepol.infer.likelihood import Likelihood
from spacepol.infer.posterior import Posterior
from spacepol.infer.prior_set import PriorSet, read_prior_file
from spacepol.priors import Fixed, LogUniform, TruncatedNormal, Uniform
from spacepol.io.measurements import Dataset
from spacepol.physics import Model


@pytest.mark.parametrize("prior", [Uniform(1.0, 3.0), LogUniform(0.01, 10.0), TruncatedNormal(1.4, 0.2, 1.0, 2.0)])
def test_rescale_is_the_inverse_cdf_and_ln_prob_integrates_to_one(prior, rng):
    u = rng.uniform(size=200000)
    x = prior.rescale(u)
    assert np.all((x >= prior.lower) & (x <= prior.upper))
    grid = np.linspace(prior.lower, prior.upper, 200001)
    density = np.exp(prior.ln_prob(grid))
    assert np.trapezoid(density, grid) == pytest.approx(1.0, abs=1e-6)
    # the histogram of rescaled uniforms matches the density (KS test, fixed seed)
    cdf = lambda v: np.interp(v, grid, np.concatenate([[0], np.cumsum((density[1:] + density[:-1]) / 2 * np.diff(grid))]))
    assert stats.kstest(x[:5000], cdf).pvalue > 0.01
    assert np.all(np.isinf(prior.ln_prob(np.array([prior.lower - 1e-6, prior.upper + 1e-6]))))


def test_prior_file_overrides_fixes_and_frees(tmp_path):
    f = tmp_path / "p.toml"
    f.write_text('[n]\ndistribution = "normal"\nmu = 1.4\nsigma = 0.1\nlower = 1.0\nupper = 2.0\n'
                 '[k]\nfixed = 0.0\n[sigma_p]\ndistribution = "loguniform"\nlower = 0.001\nupper = 0.1\n')
    priors = PriorSet(Model.from_string("paper").parameters, read_prior_file(f))
    assert priors.names == ["n", "sigma", "ks", "sigma_p", "rho_d"]  # model (effect) order
    assert priors.fixed == {"k": 0.0, "sigma_r": 0.0136, "u_p": 9.0, "v_p": 1.0}
    assert isinstance(priors.priors["n"], TruncatedNormal) and isinstance(priors.priors["k"], Fixed)


@pytest.mark.parametrize("text,message", [
    ('[n]\nlower = 2.0\nupper = 1.0\n', "lower bound 2 is not below upper bound 1"),
    ('[n]\ndistribution = "loguniform"\nlower = 0.0\nupper = 1.0\n', "lower bound must be > 0"),
    ('[k]\nlower = -1.0\nupper = 1.0\n', "reaches outside its physical range"),
    ('[n]\nlowr = 1.0\nupper = 2.0\n', "unknown key(s) lowr"),
    ('[roughness]\nfixed = 0.1\n', "no parameter(s) roughness"),
    ('[n]\ndistribution = "cauchy"\nlower = 1.0\nupper = 2.0\n', "unknown distribution 'cauchy'"),
    ('[n]\nlower = "one"\nupper = 2.0\n', "lower must be a number"),
    ('[n\n', "not valid TOML"),
])
def test_impossible_priors_are_clear_errors(tmp_path, text, message):
    from spacepol.errors import SpacepolError

    f = tmp_path / "p.toml"
    f.write_text(text)
    with pytest.raises(SpacepolError) as err:
        PriorSet(Model.from_string("paper").parameters, read_prior_file(f), where=str(f))
    assert message in str(err.value) and str(f) in str(err.value)


def _dataset(n=12, dop_err=True):
    rng = np.random.default_rng(0)
    ti, tr = np.full(n, 40.0), np.linspace(5, 75, n)
    model = Model.from_string("paper")
    data = Dataset(ti, tr, np.full(n, 180.0))
    truth = model.evaluate({"n": 1.5, "k": 0.1}, data.geometry)
    data.dop = truth.dop + 0.01 * rng.standard_normal(n)
    data.dop_err = np.full(n, 0.01) if dop_err else None
    data.brdf = truth.brdf * np.exp(0.05 * rng.standard_normal(n))
    return data, model


def test_gaussian_and_student_t_densities_match_scipy():
    data, model = _dataset()
    params = {"n": np.array([1.5, 1.6]), "k": np.array([0.1, 0.2])}
    mu = model.evaluate(params, data.geometry)
    gauss = Likelihood(data, model, observables=["dop"]).pointwise(params)
    np.testing.assert_allclose(gauss, stats.norm.logpdf(data.dop, mu.dop, 0.01), rtol=1e-12)
    robust = Likelihood(data, model, observables=["dop"], robust=True, nu=4.0).pointwise(params)
    np.testing.assert_allclose(robust, stats.t.logpdf(data.dop, 4.0, mu.dop, 0.01), rtol=1e-12)


def test_missing_errors_become_nuisance_parameters():
    data, model = _dataset(dop_err=False)
    lik = Likelihood(data, model)
    assert [p.name for p in lik.nuisance] == ["sigma_dop", "sigma_brdf_rel"]
    params = {"n": np.array([1.5]), "k": np.array([0.1]), "sigma_dop": np.array([0.02]), "sigma_brdf_rel": np.array([0.1])}
    ll = lik.pointwise(params)
    mu = model.evaluate({"n": 1.5, "k": 0.1}, data.geometry)
    np.testing.assert_allclose(ll[0, :12], stats.norm.logpdf(data.dop, mu.dop, 0.02), rtol=1e-12)
    np.testing.assert_allclose(ll[0, 12:], stats.norm.logpdf(np.log(data.brdf), np.log(mu.brdf), 0.1), rtol=1e-12)


def test_fewer_points_than_parameters_is_an_error():
    data, model = _dataset(n=3, dop_err=False)
    with pytest.raises(ParameterError, match="3 observations are fewer than the 6 free parameters"):
        Posterior.build(data, model, observables=["dop"])


def test_normalised_stokes_observables():
    """q = S1/S0, u = S2/S0 with a shared inferred noise; the model's sign convention is the data's."""
    from spacepol.paths import bundled
    from spacepol.io import read_measurements

    ptfe = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv")).at_wavelength(0.633).in_plane()
    model = Model.from_string("paper")
    lik = Likelihood(ptfe, model, observables=["q", "u"])
    assert [p.name for p in lik.nuisance] == ["sigma_qu"]
    params = {"n": np.array([1.35]), "k": np.array([0.0]), "sigma": np.array([0.3]), "ks": np.array([0.1]),
              "rho_d": np.array([0.9]), "sigma_qu": np.array([0.01])}
    pred = model.evaluate({k: v[0] for k, v in params.items() if k != "sigma_qu"}, ptfe.geometry)
    ll = lik.pointwise(params)[0]
    np.testing.assert_allclose(ll[: len(ptfe)], stats.norm.logpdf(ptfe.stokes[1] / ptfe.stokes[0], pred.stokes[1] / pred.stokes[0], 0.01), rtol=1e-12)
    # In the plane of incidence u = 0 for the model, and the specular lobe's q > 0 (s-polarized) where
    # PTFE's measured q is positive too (large angles on the specular side).
    side = (ptfe.dphi == 180.0) & (ptfe.theta_i >= 45) & (ptfe.theta_r >= 40)
    assert np.all(pred.stokes[1][side] > 0) and np.all((ptfe.stokes[1] / ptfe.stokes[0])[side] > 0)
    assert np.allclose(pred.stokes[2], 0.0, atol=1e-15)
    # by default the fullest observable measured: the Mueller matrix holds q, u and DOP, which are not counted again
    lik = Likelihood(ptfe, model)
    assert lik.observables[0] == "brdf" and lik.observables[1:] == [f"m{i}{j}" for i in range(1, 5) for j in range(1, 5)][1:]
    assert lik.left_out == {"dop": "mueller", "stokes": "mueller"}
    no_mueller = ptfe.select(np.arange(len(ptfe)))
    no_mueller.mueller = None
    assert Likelihood(no_mueller, model).observables == ["brdf", "q", "u"]  # q, u hold DOP (and AoP)
    no_mueller.stokes = None
    assert Likelihood(no_mueller, model).observables == ["dop", "brdf"]


def test_large_batches_are_blocked_and_padded_without_changing_a_value():
    """A call with thousands of sets goes through the compiled block of 16 sets (a remainder padded with a valid
    set), and through a block of 256 once the likelihood has evaluated enough sets in large calls to pay for its
    compilation: every value equals the same set's value evaluated on its own, the two block sizes agree, a
    length-1 column is shared by all blocks, and the block sizes follow the documented rule."""
    from spacepol.infer.likelihood_blocks import SETS_PAYING_A_COMPILATION, block_rows
    from spacepol.physics.geometry import default_grid

    assert [block_rows(n, [16]) for n in (5, 17, 300)] == [16, 16, 16]
    assert [block_rows(n, [16, 256]) for n in (40, 200, 300, 512)] == [16, 256, 256, 256]
    assert [block_rows(n, [16, 32]) for n in (20, 30, 100)] == [16, 32, 32]
    model, g = Model.from_string("paper"), default_grid()
    data = Dataset(g.theta_i, g.theta_r, g.dphi)
    data.dop, data.dop_err = model.evaluate({}, g).dop, np.full(g.size, 0.01)
    lik = Likelihood(data, model)
    assert lik.batch_sets % 16 == 0 and 0.99e6 < lik.batch_sets * lik.numbers_per_set <= 4e6
    rng = np.random.default_rng(5)
    n_sets = 5000  # 312 blocks of 16 and a remainder of 8 padded to 16
    sets = {"n": rng.uniform(1.2, 2.5, n_sets), "k": rng.uniform(0, 3, n_sets), "sigma": rng.uniform(0.1, 0.5, n_sets),
            "ks": rng.uniform(0.1, 0.9, n_sets), "rho_d": np.array([0.2])}
    total = lik.total(sets)
    picks = [0, 4095, 4096, 4999]
    alone = [lik.total({**{k: v[i : i + 1] for k, v in sets.items() if k != "rho_d"}, "rho_d": 0.2})[0] for i in picks]
    np.testing.assert_allclose(total[picks], alone, rtol=1e-12)
    assert np.all(np.isfinite(total)) and len(np.unique(total)) > n_sets // 2  # negative control: sets differ
    assert lik._compiled_sizes() == [16]
    for _ in range(SETS_PAYING_A_COMPILATION // n_sets):
        lik.total(sets)
    assert lik._compiled_sizes() == [16, 256]  # 19 blocks of 256 and a remainder of 136 in blocks of 16
    np.testing.assert_allclose(lik.total(sets), total, rtol=1e-12)


def _mueller_set(size: int):
    from spacepol.physics.geometry import Geometry

    rng = np.random.default_rng(3)
    g = Geometry(rng.uniform(0, 70, size), rng.uniform(0, 75, size), rng.uniform(0, 360, size))
    model = Model.from_string("specular+smith+subsurface+volume")
    data = Dataset(g.theta_i, g.theta_r, g.dphi)
    mueller = model.evaluate({"n": 1.35, "k": 0.0, "sigma": 0.3}, g, mueller=True).mueller
    data.mueller = mueller * (1 + 0.01 * rng.standard_normal(mueller.shape))
    data.mueller_err = np.abs(mueller) * 0.01 + 1e-3
    data.brdf, data.brdf_err = mueller[0, 0], 0.02 * mueller[0, 0]
    return model, data


def test_a_large_likelihood_compiles_one_block_size_and_keeps_every_value():
    """Full Mueller on 300 geometries: calls of 5, 40 and 100 sets all go through the one compiled block of 16
    (padded with a valid set), each value equal to that set evaluated alone, and no larger block is compiled however
    many sets it has evaluated; a small likelihood (the negative control) compiles the block of 256 once it has."""
    model, data = _mueller_set(300)
    lik = Likelihood(data, model, observables=["mueller"])
    assert lik.compiles_one_block
    rng = np.random.default_rng(8)
    sets = {"n": rng.uniform(1.2, 1.6, 100), "k": np.zeros(100), "sigma": rng.uniform(0.1, 0.5, 100)}
    totals = [lik.total({k: v[:m] for k, v in sets.items()}) for m in (5, 40, 100)]
    (key, jitted), = lik._jitted.items()
    assert jitted._cache_size() == 1
    alone = [lik.total({k: v[i : i + 1] for k, v in sets.items()})[0] for i in (0, 17, 99)]
    np.testing.assert_allclose(totals[2][[0, 17, 99]], alone, rtol=1e-12)
    np.testing.assert_allclose(totals[1], totals[2][:40], rtol=1e-12)
    # the pointwise values come from that same program (a model diagnose refits compiles one likelihood, not two),
    # and the total is their sum; the fused total of the small likelihood (below) agrees with its pointwise sum too
    pointwise = lik.pointwise({k: v[:40] for k, v in sets.items()})
    assert pointwise.shape == (40, lik.n_obs) and len(lik._jitted) == 1
    np.testing.assert_allclose(pointwise.sum(axis=1), totals[1], rtol=1e-12)
    # a block too large for the unfused values to stay in the cache (1,024 sets x 4,800 numbers) is summed fused
    lik.exact_sizes.add(1024)
    many = {k: np.resize(v, 1024) for k, v in sets.items()}
    np.testing.assert_allclose(lik.total(many)[:100], totals[2], rtol=1e-12)
    assert len(lik._jitted) == 2
    small_model, small_data = _mueller_set(20)
    small = Likelihood(small_data, small_model, observables=["mueller"])
    assert not small.compiles_one_block
    for m in (5, 40, 100):
        small.total({k: v[:m] for k, v in sets.items()})
    (key, jitted), = small._jitted.items()
    assert jitted._cache_size() == 1
    # the count of sets evaluated in large calls, as a long run leaves it
    small._sets_in_large_calls = lik._sets_in_large_calls = 10**6
    small.total({k: np.resize(v, 300) for k, v in sets.items()})
    assert jitted._cache_size() == 2 and small._compiled_sizes() == [16, 256]
    assert lik._compiled_sizes() == [16, 1024]  # the large one: its block and the exact size only
    few = {k: v[:5] for k, v in sets.items()}
    np.testing.assert_allclose(small.pointwise(few).sum(axis=1), small.total(few), rtol=1e-12)
    assert len(small._jitted) == 2  # negative control: the small likelihood's total is a program of its own


def test_a_fixed_index_under_the_interface_equals_the_same_index_free():
    """n held fixed (a prior file's `n = 1.35`, compiled in as a scalar) under subsurface and volume, whose
    interface rows then have no axis of sets: the same values as n = 1.35 given per set (this raised a
    broadcasting error before)."""
    model, data = _mueller_set(40)
    rng = np.random.default_rng(2)
    free = Posterior.build(data, model)
    fixed = Posterior.build(data, model, {"n": Fixed(1.35)})
    theta_fixed = fixed.priors.sample(rng, 6)
    params = fixed.priors.to_params(theta_fixed)
    theta_free = np.column_stack([np.full(6, 1.35) if name == "n" else params[name] * np.ones(6) for name in free.priors.names])
    np.testing.assert_allclose(fixed.log_likelihood(theta_fixed), free.log_likelihood(theta_free), rtol=1e-12)
    assert np.ptp(fixed.log_likelihood(theta_fixed)) > 0  # the sets differ


def test_a_samplers_parameter_matrix_gives_the_dict_paths_values_through_the_same_program(tmp_path):
    """``Posterior.summed_log_likelihood`` hands the compiled program the rows of theta as they are
    (``Likelihood.of_matrix``): bitwise the values of the dict path (``total`` of ``to_params``), a held parameter
    compiled in alike, and no second program compiled; control: another set gives another value."""
    from spacepol.physics.geometry import default_grid

    model, g = Model.from_string("paper"), default_grid()
    data = Dataset(g.theta_i, g.theta_r, g.dphi)
    data.dop, data.dop_err = model.evaluate({}, g).dop, np.full(g.size, 0.01)
    prior = tmp_path / "p.toml"
    prior.write_text("[rho_d]\nfixed = 0.3\n")
    post = Posterior.build(data, model, read_prior_file(prior))
    assert post.priors.fixed["rho_d"] == 0.3 and "rho_d" not in post.priors.names
    theta = post.priors.sample(np.random.default_rng(8), 16)
    fast = post.summed_log_likelihood(theta)
    compiled = set(post.likelihood._jitted)
    slow = post.likelihood.total(post.priors.to_params(theta))
    np.testing.assert_array_equal(fast, slow)
    assert set(post.likelihood._jitted) == compiled and len(compiled) == 1
    assert len(np.unique(fast)) == len(theta)
