"""Gradient methods: the posterior's JAX gradient, the logit sampling space, NUTS and the multistart L-BFGS."""

import numpy as np
import pytest

from spacepol.infer.differentiable import cube_objective
from spacepol.infer.objective import NegativeLogPosterior
from spacepol.infer.posterior import Posterior
from spacepol.priors import LogUniform, TruncatedNormal, Uniform
from spacepol.infer.sampling_space import SamplingSpace
from spacepol.io.measurements import Dataset
from spacepol.physics import Model
from spacepol.physics.geometry import default_grid

TRUTH = {"n": 1.24, "k": 6.6, "sigma": 0.2, "ks": 0.5, "rho_d": 0.1}
MIXED = {"n": TruncatedNormal(1.3, 0.2, 0.5, 3.0), "sigma": LogUniform(0.02, 0.8), "k": Uniform(0.0, 20.0)}


def dop_posterior(priors=None, seed=0):
    model = Model.from_string("paper")
    g = default_grid()
    data = Dataset(g.theta_i, g.theta_r, g.dphi)
    rng = np.random.default_rng(seed)
    data.dop = model.evaluate(TRUTH, data.geometry).dop + 0.005 * rng.standard_normal(g.size)
    data.dop_err = np.full(g.size, 0.005)
    return Posterior.build(data, model, priors)


def test_logit_space_round_trips_and_keeps_the_declared_prior_density():
    """theta -> z -> theta is the identity, and log p(z) = log prior(theta) + log |d theta / d z| (numerically)."""
    post = dop_posterior(MIXED)
    space = SamplingSpace(post.priors)
    theta = post.priors.sample(np.random.default_rng(1), 50)
    z = space.to_z(theta)
    np.testing.assert_allclose(space.to_theta(z), theta, rtol=1e-10, atol=1e-12)
    h = 1e-6
    for j in range(post.ndim):
        dz = np.zeros_like(z)
        dz[:, j] = h
        dtheta = (space.to_theta(z + dz)[:, j] - space.to_theta(z - dz)[:, j]) / (2 * h)
        lp_j = np.array([post.priors.priors[post.names[j]].ln_prob(t) for t in theta[:, j]])
        logistic = -np.abs(z[:, j]) - 2 * np.log1p(np.exp(-np.abs(z[:, j])))
        np.testing.assert_allclose(lp_j + np.log(dtheta), logistic, atol=1e-6)


def test_cube_gradient_equals_finite_differences_and_the_value_the_negative_log_posterior():
    post = dop_posterior(MIXED)
    f = cube_objective(post)
    objective = NegativeLogPosterior(post)
    rng = np.random.default_rng(2)
    for u in rng.uniform(0.1, 0.9, size=(4, post.ndim)):
        value, grad = f(u)
        assert value == pytest.approx(float(objective(post.priors.rescale(u[None, :]))[0]), rel=1e-10)
        h = 1e-6
        fd = [(f(u + h * e)[0] - f(u - h * e)[0]) / (2 * h) for e in np.eye(post.ndim)]
        np.testing.assert_allclose(grad, fd, rtol=1e-5, atol=1e-3 * max(1.0, np.max(np.abs(fd))))
    # negative control: a gradient of another posterior (the data shifted) is not this one's
    other = cube_objective(dop_posterior(MIXED, seed=5))
    assert not np.allclose(other(u)[1], f(u)[1], rtol=1e-3)


@pytest.mark.parametrize("spec,held", [("specular+smith+subsurface", {"k": 0.0}), ("phase_matrix", {})])
def test_the_gradient_is_finite_for_a_dielectric_and_through_the_volumes_interface(spec, held):
    """A dielectric's k = 0 (B = 0 in N cos(theta_t) = A + iB) and the phase-matrix volume's own interface gave the
    index an infinite-times-zero (NaN) derivative, which the optimizers read as 0 and NUTS as no force: on NIST's
    PTFE rows, at random prior points, every component of the cube gradient is finite and equals central finite
    differences. Negative control: the same rows with another index give another gradient."""
    from spacepol.io import read_measurements
    from spacepol.paths import bundled
    from spacepol.priors import Fixed

    data = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv")).at_wavelength(0.633)
    data = data.select(np.arange(0, len(data), 16))
    post = Posterior.build(data, Model.from_string(spec), {name: Fixed(v) for name, v in held.items()})
    f = cube_objective(post)
    index = [j for j, name in enumerate(post.names) if name in ("n", "n_pm")]
    rng = np.random.default_rng(3)
    for u in rng.uniform(0.2, 0.8, size=(2, post.ndim)):
        _, grad = f(u)
        h = 1e-6
        fd = np.array([(f(u + h * e)[0] - f(u - h * e)[0]) / (2 * h) for e in np.eye(post.ndim)[index]])
        assert np.all(np.isfinite(fd)) and np.all(fd != 0), fd
        np.testing.assert_allclose(grad[index], fd, rtol=1e-4, atol=1e-6 * np.max(np.abs(fd)))
    moved = u.copy()
    moved[index[0]] = 0.5 * moved[index[0]]
    assert not np.allclose(f(moved)[1][index], grad[index], rtol=1e-2)


def _ess(samples):
    """Smallest bulk ESS over parameters of (draws, chains, D) samples (ArviZ)."""
    import arviz as az

    data = az.convert_to_dataset({f"p{j}": samples[:, :, j].T for j in range(samples.shape[2])})
    return float(az.ess(data, method="bulk").to_array().min())


def _prior_only_check(result, priors, names):
    """Each marginal's prior CDF values should be uniform on [0, 1]: mean 1/2 and 10 % below 0.1, within 4 MC
    standard errors from the ESS. Returns the worst deviation in standard errors."""
    ess = _ess(result.samples)
    flat = result.flat_samples()
    worst = 0.0
    for j, name in enumerate(names):
        u = priors[name].cdf(flat[:, j])
        worst = max(worst, abs(u.mean() - 0.5) / np.sqrt(1 / 12 / ess), abs(np.mean(u < 0.1) - 0.1) / np.sqrt(0.09 / ess))
    return worst


@pytest.mark.parametrize("engine,declared", [("emcee", ()), ("nuts", ()), ("emcee", ("sigma",))])
def test_prior_only_run_returns_the_declared_priors(engine, declared):
    """Non-uniform priors (truncated normal, log-uniform) sampled through the logit space (and, for emcee, with
    sigma kept in its own coordinates) come back as declared: the Jacobian is right. Negative control: the same samples
    judged against a wrong prior fail."""
    from spacepol.infer.engines.emcee_sampler import sample_emcee
    from spacepol.infer.engines.nuts import sample_nuts

    post = dop_posterior(MIXED)
    post.prior_only = True
    space = SamplingSpace(post.priors, declared=declared)
    if engine == "emcee":
        res = sample_emcee(post, np.random.default_rng(3), walkers=32, max_steps=3000, progress=False, initial="prior",
                           space=space)
    else:
        res = sample_nuts(post, np.random.default_rng(3), warmup=300, draws=1000, max_draws=1000, progress=False,
                          initial="prior", space=space)
    priors = post.priors.priors
    assert _prior_only_check(res, priors, res.names) < 4
    wrong = dict(priors, n=Uniform(0.5, 3.0), sigma=Uniform(0.02, 0.8))
    assert _prior_only_check(res, wrong, res.names) > 6


def test_a_parameter_whose_posterior_reaches_its_bound_keeps_its_own_coordinates():
    """k of a dielectric (truth 0, R depends on k^2): the log posterior hardly changes with k moved to 0, so k
    stays declared; moving n, sigma or rho_d alone to a bound ruins the DOP, so they keep the logit. On the
    k_s/rho_d ridge (DOP alone) n, k, sigma keep it too (k_s may not: the wedge's mass lies against k_s = 1)."""
    from spacepol.infer.optimum import find_optimum
    from spacepol.infer.sampling_space import reaching_a_bound

    model = Model.from_string("paper")
    g = default_grid()
    data = Dataset(g.theta_i, g.theta_r, g.dphi)
    truth = {**TRUTH, "n": 1.5, "k": 0.0}
    data.dop = model.evaluate(truth, data.geometry).dop + 0.005 * np.random.default_rng(1).standard_normal(g.size)
    data.dop_err = np.full(g.size, 0.005)
    post = Posterior.build(data, model)
    _, centre = find_optimum(post, np.random.default_rng(0))
    assert reaching_a_bound(post, centre) == ["k"]
    ridge = dop_posterior()
    assert not {"n", "k", "sigma", "rho_d"} & set(reaching_a_bound(ridge, find_optimum(ridge, np.random.default_rng(0))[1]))


@pytest.mark.slow  # the fast NUTS check is the prior-only run above
def test_nuts_and_emcee_reach_the_same_posterior_on_the_ridge():
    """On DOP alone (the k_s/rho_d ridge) both engines' 5/50/95 % quantiles agree within 4 combined Monte-Carlo
    standard errors (from each run's ESS); NUTS takes ~10 leapfrog steps a draw in the logit space.
    Negative control: NUTS on data with other noise does not agree with this emcee run."""
    from spacepol.infer.engines.emcee_sampler import sample_emcee
    from spacepol.infer.engines.nuts import sample_nuts

    post = dop_posterior()
    # emcee mixes slowly along this band (acceptance 0.19, tau ~100): with seed 4 its R-hat was still 1.02 at the
    # default cap of 20,000 steps and reached 1.01 at 29,500, so the cap is raised; "not capped" is still required
    a = sample_emcee(post, np.random.default_rng(4), progress=False, max_steps=60000)
    b = sample_nuts(post, np.random.default_rng(4), progress=False)
    assert not a.info["capped"] and not b.info["capped"]
    assert b.info["leapfrog_per_draw"] < 30

    def disagreement(x, y):
        worst = 0.0
        ess_x, ess_y = _ess(x.samples), _ess(y.samples)
        fx, fy = x.flat_samples(), y.flat_samples()
        for j in range(fx.shape[1]):
            for q in (5, 50, 95):
                # standard error of a quantile: sqrt(q(1-q)/ESS) / density, the density from the pooled draws
                pooled = np.concatenate([fx[:, j], fy[:, j]])
                lo, hi = np.percentile(pooled, [max(q - 5, 0.5), min(q + 5, 99.5)])
                density = (min(q + 5, 99.5) - max(q - 5, 0.5)) / 100 / (hi - lo)
                se = np.sqrt(q / 100 * (1 - q / 100)) / density * np.sqrt(1 / ess_x + 1 / ess_y)
                worst = max(worst, abs(np.percentile(fx[:, j], q) - np.percentile(fy[:, j], q)) / se)
        return worst

    assert disagreement(a, b) < 4
    other = sample_nuts(dop_posterior(seed=9), np.random.default_rng(4), progress=False)
    assert disagreement(a, other) > 4


def test_the_multistart_with_exact_gradients_reaches_the_finite_difference_maximum():
    """NIST's PTFE in the plane of incidence at 0.633 um under a dielectric facet model (k = 0) with a subsurface
    term, its noise levels profiled: the multistart polished by exact JAX gradients ends at the same maximum as the
    one polished by finite differences from the same Sobol points (the margin is printed). Control: a scan of the
    prior alone is far below."""
    from scipy.stats import qmc

    from spacepol.infer.optimum import multistart
    from spacepol.infer.profiled import ProfiledPosterior
    from spacepol.io import read_measurements
    from spacepol.paths import bundled
    from spacepol.priors import Fixed

    data = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv")).at_wavelength(0.633).in_plane()
    post = ProfiledPosterior.of(Posterior.build(data, Model.from_string("specular+smith+subsurface"), {"k": Fixed(0.0)}))
    exact, _ = multistart(post, np.random.default_rng(0), gradient=True)
    finite, _ = multistart(post, np.random.default_rng(0), gradient=False)
    assert abs(exact - finite) < 1.0, f"exact gradients {exact:.2f}, finite differences {finite:.2f}"
    scan = post.log_prob(post.priors.rescale(qmc.Sobol(post.ndim, rng=np.random.default_rng(1)).random(256)))
    assert np.max(scan) < exact - 100, (np.max(scan), exact)
