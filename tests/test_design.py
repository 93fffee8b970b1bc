"""Experiment design on a DOP-only synthetic set: the k_s / rho_d ridge is found, the measurements that
break it are named (BRDF; DOP or normalised Mueller elements cannot: they are ratios of intensities), and
adding them (synthetic) shrinks the posterior along it, measured with emcee; adding DOP does not."""

import numpy as np
import pytest

from spacepol.criticism.design import design
from spacepol.infer.inversion import invert
from spacepol.infer.posterior import Posterior
from spacepol.io.measurements import Dataset
from spacepol.physics import Geometry, Model
from spacepol.physics.geometry import default_grid

TRUTH = {"n": 1.5, "k": 0.0, "sigma": 0.25, "ks": 0.5, "rho_d": 0.2}
NOISE_DOP, NOISE_BRDF = 0.005, 0.05
UNINFORMATIVE = 1e6  # an error this large makes a number carry no information (a gap in the table)


def measured(geometry, rng, dop_err, brdf_err_rel):
    """Synthetic DOP and BRDF of the truth at ``geometry``, with per-row errors (huge where not measured)."""
    pred = Model.from_string("paper").evaluate(TRUTH, geometry)
    data = Dataset(geometry.theta_i, geometry.theta_r, geometry.dphi)
    data.dop = np.clip(pred.dop + np.minimum(dop_err, NOISE_DOP) * rng.standard_normal(geometry.size), 0, 1)
    data.dop_err = dop_err
    data.brdf = pred.brdf * (1 + np.minimum(brdf_err_rel, NOISE_BRDF) * rng.standard_normal(geometry.size))
    data.brdf_err = brdf_err_rel * pred.brdf
    return data


def with_rows(base_geometry, extra, observable, rng):
    """The DOP-only set plus ``extra`` rows [(theta_i, theta_r, dphi)] measuring ``observable`` alone."""
    n, m = base_geometry.size, len(extra)
    ti, tr, dp = (np.concatenate([getattr(base_geometry, a), [e[k] for e in extra]]) for k, a in
                  enumerate(("theta_i", "theta_r", "dphi")))
    dop_err = np.concatenate([np.full(n, NOISE_DOP), np.full(m, NOISE_DOP if observable == "dop" else UNINFORMATIVE)])
    brdf_err = np.concatenate([np.full(n, UNINFORMATIVE), np.full(m, NOISE_BRDF if observable == "brdf" else UNINFORMATIVE)])
    return measured(Geometry(ti, tr, dp), rng, dop_err, brdf_err)


def ks_spread(data, seed=1):
    """90 % width of log k_s and log rho_d under the posterior (emcee, converged)."""
    posterior = Posterior.build(data, Model.from_string("paper"))
    flat = invert(posterior, seed=seed, progress=False).draws.flat_samples()
    names = posterior.priors.names
    widths = [np.subtract(*np.percentile(np.log(flat[:, names.index(n)]), [95, 5])) for n in ("ks", "rho_d")]
    return np.array(widths)


@pytest.fixture(scope="module")
def dop_only():
    grid = default_grid()
    rng = np.random.default_rng(3)
    data = measured(grid, rng, np.full(grid.size, NOISE_DOP), np.full(grid.size, UNINFORMATIVE))
    return data, design(Posterior.build(data, Model.from_string("paper")), TRUTH, noise={"brdf": NOISE_BRDF})


def test_the_ridge_is_named_and_only_brdf_breaks_it(dop_only):
    _, report = dop_only
    assert set(report["ridge"]["parameters"]) == {"ks", "rho_d"}
    assert report["ridge"]["sd_relative_to_prior"] > 0.9  # DOP alone: the ridge is as wide as the prior
    assert all(p["observable"] == "brdf" for p in report["picks"])
    assert report["picks"][-1]["shrink"] > 5
    # DOP and m_ij = M_ij / M_11 are ratios of intensities: no single one helps
    assert report["best_single"]["dop"]["shrink"] < 1.01 and report["best_single"]["mueller"]["shrink"] < 1.01
    assert "BRDF at theta_i" in report["findings"][0]


@pytest.mark.slow
def test_adding_the_named_measurements_shrinks_the_posterior_and_dop_does_not(dop_only):
    data, report = dop_only
    rng = np.random.default_rng(4)
    before = ks_spread(data)
    picks = [(p["theta_i"], p["theta_r"], p["dphi"]) for p in report["picks"]]
    after = ks_spread(with_rows(data.geometry, picks, "brdf", rng))
    control = ks_spread(with_rows(data.geometry, picks, "dop", rng))
    print(f"90 % width of log ks, log rho_d: DOP only {before}, + 3 BRDF {after}, + 3 DOP {control}")
    assert np.all(before / after > 3)
    assert np.all(before / control < 1.5)


def test_a_parameter_at_its_prior_bound_is_named_and_kept_out_of_the_ridge(dop_only):
    """At the truth k = 0 (a dielectric, the k prior's lower bound) the DOP has no first-order information on
    k (it depends on k^2): k is reported as at its bound, not as the ridge (it tied with k_s/rho_d)."""
    _, report = dop_only
    assert report["ridge"]["at_prior_bound"] == ["k"] and report["ridge"]["direction"]["k"] == 0.0
    assert any("k = 0" in f and "bound" in f for f in report["findings"])
