"""Noise the data measure themselves (infer.measured_noise): reciprocal pairs and repeated geometries estimate
each inferred noise group without a model; the estimate is the floor of the inferred level's prior, and runs
report misfit = inferred / measured."""

import numpy as np
import pytest

from scatmech_sets import ptfe_like_geometry
from spacepol.infer.likelihood import Likelihood
from spacepol.infer.measured_noise import measure, reciprocal_pairs, repeated_pairs
from spacepol.infer.posterior import Posterior
from spacepol.io.measurements import Dataset
from spacepol.physics import Model
from spacepol.physics.geometry import default_grid

TRUTH = {"n": 1.4, "k": 0.0, "sigma": 0.3, "ks": 0.3, "rho_s": 0.8}
GROUPS = ("sigma_m_pol", "sigma_m_lin", "sigma_m_circ")


def _mueller_set(noise_m, seed=0, noise_brdf=0.03):
    """specular+subsurface at the PTFE-like geometries (they hold 13 reciprocal pairs), no errors in the file."""
    g = ptfe_like_geometry()
    m = Model.from_string("specular+subsurface").evaluate(TRUTH, g, mueller=True).mueller
    rng = np.random.default_rng(seed)
    normalised = m / m[0, 0] + noise_m * rng.standard_normal(m.shape)
    normalised[0, 0] = 1.0
    brdf = m[0, 0] * np.exp(noise_brdf * rng.standard_normal(g.size))
    data = Dataset(g.theta_i, g.theta_r, g.dphi, wavelength_um=np.full(g.size, 0.633))
    data.mueller, data.brdf = normalised * brdf, brdf
    data.source = "render"
    return data


@pytest.mark.parametrize("noise", [0.012, 0.03])
def test_reciprocal_pairs_measure_the_noise_of_each_group(noise):
    data = _mueller_set(noise)
    assert len(reciprocal_pairs(data)) >= 10 and len(repeated_pairs(data)) == 0
    measured = measure(Likelihood(data, Model.from_string("specular+subsurface")))
    assert set(GROUPS) <= set(measured)
    for group in GROUPS:
        m = measured[group]
        assert m.source == "reciprocal pairs" and m.n_differences >= 40
        # within 3 standard errors of the truth, and (negative control) not of the other noise level
        assert abs(m.value - noise) < 3 * m.standard_error, (group, m.value, m.standard_error)
        other = 0.03 if noise == 0.012 else 0.012
        assert abs(m.value - other) > 3 * m.standard_error


def test_repeated_geometries_measure_dop_noise_and_too_few_measure_nothing():
    g = default_grid()
    dop = Model.from_string("paper").evaluate({"n": 1.5, "k": 0.0, "sigma": 0.2, "ks": 0.5, "rho_d": 0.1}, g).dop
    rng = np.random.default_rng(1)
    twice = np.concatenate([dop, dop]) + 0.01 * rng.standard_normal(2 * g.size)
    data = Dataset(np.tile(g.theta_i, 2), np.tile(g.theta_r, 2), np.tile(g.dphi, 2))
    data.dop, data.source = twice, "twice"
    measured = measure(Likelihood(data, Model.from_string("paper")))
    m = measured["sigma_dop"]
    assert m.source == "repeated geometries" and m.n_differences == g.size
    assert abs(m.value - 0.01) < 3 * m.standard_error
    once = data.select(np.arange(g.size + 10))  # only 10 repeats: fewer than 20 differences measure nothing
    assert measure(Likelihood(once, Model.from_string("paper"))) == {}


def test_the_measured_noise_floors_the_inferred_noise_and_runs_report_the_misfit():
    data = _mueller_set(0.012)
    posterior = Posterior.build(data, Model.from_string("specular+subsurface"))
    for group in GROUPS:
        floor = posterior.measured_noise[group].floor
        assert posterior.priors.priors[group].lower == pytest.approx(floor) and 0.5 * 0.012 < floor < 0.012
    free = Posterior.build(data, Model.from_string("specular+subsurface"), noise_floor=False)
    assert free.priors.priors["sigma_m_lin"].lower == pytest.approx(1e-4)
    from spacepol.infer.draws_result import explains, noise_findings, noise_ratios

    summary_parameters = {g: {"median": 0.012 * r} for g, r in zip(GROUPS, (1.0, 1.2, 2.0))}
    noise = noise_ratios(posterior, summary_parameters)
    assert noise["sigma_m_circ"]["ratio"] == pytest.approx(0.024 / posterior.measured_noise["sigma_m_circ"].value)
    assert not explains(noise) and any("NOT explained" in line for line in noise_findings(noise))
