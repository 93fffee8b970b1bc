"""The light-curve likelihood's densities of DoLP and AoP (``detect.light_curve_likelihood``) against independent
ones: scipy's Rice distribution, the bivariate Gaussian of the normalized Stokes parameters q and u, and draws of q
and u with Gaussian noise; and why they matter: a Gaussian about the true DoLP is biased where the polarization is
near its noise."""

from types import SimpleNamespace

import numpy as np
import pytest
from scipy import integrate, optimize, stats

from spacepol.detect.light_curve_likelihood import angle_log_pdf, pointwise, replicates, rice_log_pdf


def test_the_dolp_density_is_scipys_rice():
    x = np.linspace(1e-4, 0.2, 50)
    for true, sigma in [(0.0, 0.01), (0.01, 0.015), (0.1, 0.01), (0.4, 1e-4)]:
        expected = stats.rice.logpdf(x, true / sigma, scale=sigma)
        finite = np.isfinite(expected)
        np.testing.assert_allclose(rice_log_pdf(x, true, sigma)[finite], expected[finite], rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("true, sigma", [(0.0, 0.01), (0.01, 0.01), (0.05, 0.01), (0.3, 1e-3)])
def test_the_aop_density_is_that_of_noisy_q_and_u(true, sigma):
    """It integrates to 1 over 180 deg, and 20,000 angles of (q, u) drawn with Gaussian noise about (true, 0) pass a
    Kolmogorov-Smirnov test against it (p > 0.01 at a fixed seed); control: the Gaussian of the delta method (sigma /
    (2 DoLP) rad) on the same draws fails it where the polarization is near its noise."""
    density = lambda d: np.exp(angle_log_pdf(d, true, sigma))  # noqa: E731
    width = 90.0 if true < 10 * sigma else 20 * np.degrees(sigma / (2 * true))
    area = integrate.quad(density, -width, width, limit=200, points=[0.0])[0]
    assert abs(area - 1.0) < 1e-6, area
    rng = np.random.default_rng(3)
    q, u = true + sigma * rng.standard_normal(20000), sigma * rng.standard_normal(20000)
    angles = 0.5 * np.degrees(np.arctan2(u, q))
    grid = np.linspace(-width, width, 40001)
    cdf = integrate.cumulative_trapezoid(density(grid), grid, initial=0.0)
    p = stats.kstest(angles, lambda a: np.interp(a, grid, cdf / cdf[-1])).pvalue
    assert p > 0.01, p
    if 0 < true < 2 * sigma:
        delta_method = stats.norm(0.0, np.degrees(sigma / (2 * true)))
        assert stats.kstest(angles, delta_method.cdf).pvalue < 1e-6


def _curve(dolp, dolp_err, aop_deg, aop_err_deg):
    return SimpleNamespace(flux=None, flux_err=None, dolp=np.atleast_1d(dolp), dolp_err=np.atleast_1d(dolp_err),
                           aop_deg=np.atleast_1d(aop_deg), aop_err_deg=np.atleast_1d(aop_err_deg))


def test_dolp_and_aop_together_are_the_bivariate_gaussian_of_q_and_u():
    """The pair's two terms sum to the density of the measured (q, u) about the model's, times the Jacobian to
    (DoLP, AoP in degrees), where the file's AoP error is the delta method's (as ``synth_pass`` writes it), at low and
    high polarization alike."""
    rng = np.random.default_rng(1)
    for sigma, true in [(0.015, 0.01), (0.01, 0.3), (1e-4, 0.05)]:
        measured_q, measured_u = true + sigma * rng.standard_normal(8), 0.3 * true + sigma * rng.standard_normal(8)
        dolp, aop = np.hypot(measured_q, measured_u), 0.5 * np.degrees(np.arctan2(measured_u, measured_q))
        curve = _curve(dolp, sigma, aop, np.degrees(sigma / (2 * dolp)))
        model_dolp, model_aop = np.full((1, 8), 1.3 * true), np.full((1, 8), 10.0)
        terms = pointwise(curve, ["dolp", "aop_deg"], {"flux": np.zeros((1, 8)), "dolp": model_dolp, "aop_deg": model_aop})
        q0, u0 = 1.3 * true * np.cos(np.radians(20.0)), 1.3 * true * np.sin(np.radians(20.0))
        expected = (stats.norm.logpdf(measured_q, q0, sigma) + stats.norm.logpdf(measured_u, u0, sigma)
                    + np.log(2 * dolp * np.pi / 180))
        np.testing.assert_allclose(terms[0, :8] + terms[0, 8:], expected, rtol=1e-10)


def test_near_its_noise_the_rice_density_finds_the_true_dolp_and_a_gaussian_does_not():
    """400 DoLPs measured of a true 0.01 with noise 0.015 per component: the maximum of the summed Rice density lies
    within 3 of its standard errors of the truth; control: the Gaussian's (the measured mean) lies above by more than 10."""
    rng = np.random.default_rng(7)
    true, sigma, n = 0.01, 0.015, 400
    measured = np.hypot(true + sigma * rng.standard_normal(n), sigma * rng.standard_normal(n))
    fit = optimize.minimize_scalar(lambda p: -rice_log_pdf(measured, p, sigma).sum(), bounds=(0, 0.1), method="bounded")
    curvature = -np.diff(rice_log_pdf(measured, fit.x + np.array([-1e-4, 0, 1e-4])[:, None], sigma).sum(axis=1), 2)[0] / 1e-8
    se = 1 / np.sqrt(curvature)
    assert abs(fit.x - true) < 3 * se, (fit.x, se)
    assert measured.mean() - true > 10 * sigma / np.sqrt(n), measured.mean()


def test_replicated_dolp_carries_the_measured_ones_bias():
    """The posterior predictive draws DoLP from q and u: its mean matches measured DoLPs of the same truth, not the
    truth itself (within 4 Monte-Carlo SE); the AoP's replicates centre on the model's (their circular mean)."""
    rng = np.random.default_rng(2)
    curve = _curve(np.full(3, 0.02), np.full(3, 0.015), np.zeros(3), np.full(3, 20.0))
    mu = {"flux": np.zeros((20000, 3)), "dolp": np.full((20000, 3), 0.01), "aop_deg": np.full((20000, 3), 30.0)}
    out = replicates(curve, mu, rng)
    expected = stats.rice.mean(0.01 / 0.015, scale=0.015)
    assert abs(out["dolp"].mean() - expected) < 4 * out["dolp"].std() / np.sqrt(out["dolp"].size)
    assert out["dolp"].mean() > 0.01 + 0.005  # control: far above the truth
    circular_mean = 0.5 * np.degrees(np.angle(np.exp(2j * np.radians(out["aop_deg"])).mean()))
    assert abs(circular_mean - 30.0) < 2.0, circular_mean


def test_far_above_the_noise_the_pair_is_the_gaussian_of_dolp_and_of_aop():
    """At DoLP 0.3 +- 1e-4 each term agrees with the Gaussian of its own observable (AoP on its circle, the delta
    method's error) to 1e-3 in log density; control: near the noise (DoLP 0.02 +- 0.015) they differ by more than 0.1."""
    def terms(true, sigma, measured_dolp, measured_aop):
        curve = _curve(measured_dolp, sigma, measured_aop, np.degrees(sigma / (2 * measured_dolp)))
        mu = {"flux": np.zeros((1, 1)), "dolp": np.full((1, 1), true), "aop_deg": np.full((1, 1), 12.0)}
        new = pointwise(curve, ["dolp", "aop_deg"], mu)[0]
        old = [stats.norm.logpdf(measured_dolp, true, sigma),
               stats.norm.logpdf(measured_aop, 12.0, np.degrees(sigma / (2 * measured_dolp)))]
        return new, np.array(old)

    new, old = terms(0.3, 1e-4, 0.3 + 1.2e-4, 12.0 + 0.011)
    np.testing.assert_allclose(new, old, atol=1e-3)
    new, old = terms(0.02, 0.015, 0.035, 30.0)
    assert np.max(np.abs(new - old)) > 0.1
