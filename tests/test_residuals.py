"""Residual structure: runs, autocorrelation and trends of standardised residuals."""

import numpy as np
import pytest

from spacepol.infer.residuals import analyse, lag1, runs_test, sweeps
from spacepol.infer.engines.emcee_sampler import sample_emcee
from spacepol.infer.posterior import Posterior
from spacepol.io.measurements import Dataset
from spacepol.physics import Model


def test_runs_statistic_is_standard_normal_for_noise():
    """Under iid noise the pooled runs z-score is ~N(0, 1): checked over 2000 simulated sets."""
    rng = np.random.default_rng(4)
    groups = [np.arange(i * 12, (i + 1) * 12) for i in range(6)]
    z = np.array([runs_test(rng.standard_normal(72), groups)["z"] for _ in range(2000)])
    assert abs(z.mean()) < 4 / np.sqrt(2000) + 0.05  # continuity: discreteness biases z slightly
    assert abs(z.std() - 1) < 0.1
    # negative control: a smooth misfit (a slow sine along each sweep) has far too few runs
    smooth = np.concatenate([np.sin(np.linspace(0, np.pi, 12)) - 0.5 for _ in groups])
    assert runs_test(smooth + 0.05 * rng.standard_normal(72), groups)["p"] < 1e-3
    assert lag1(smooth, groups) > 0.5


def _data(spec, truth, seed, wavelength_um=None):
    rng = np.random.default_rng(seed)
    ti = np.repeat([20.0, 40.0, 60.0], 14)
    tr = np.tile(np.linspace(0, 80, 14), 3)
    data = Dataset(ti, tr, np.where(np.arange(ti.size) % 2, 180.0, 0.0),
                   wavelength_um=None if wavelength_um is None else np.full(ti.size, wavelength_um))
    pred = Model.from_string(spec).evaluate(truth, data.geometry)
    data.dop = pred.dop + 0.005 * rng.standard_normal(ti.size)
    data.dop_err = np.full(ti.size, 0.005)
    data.brdf = pred.brdf * (1 + 0.03 * rng.standard_normal(ti.size))
    data.brdf_err = 0.03 * pred.brdf
    return data


TRUTH = {"n": 1.5, "k": 0.0, "sigma": 0.25, "ks": 0.6, "rho_d": 0.3, "rho_pd": 0.4}


@pytest.mark.parametrize("hidden,expect_structure", [(False, False), (True, True)])
def test_a_hidden_effect_leaves_structure_and_a_good_model_does_not(hidden, expect_structure):
    spec = "paper+polarized_diffuse" if hidden else "paper"
    data = _data(spec, {k: v for k, v in TRUTH.items() if k != "rho_pd" or hidden}, seed=9)
    post = Posterior.build(data, Model.from_string("paper"))
    res = sample_emcee(post, np.random.default_rng(2), progress=False, max_steps=3000)
    report = analyse(post, res.flat_samples())
    structured = report.runs["dop"]["p"] < 0.01 or any(t["p"] < 0.01 for t in report.trends["dop"].values())
    assert structured == expect_structure, report.findings()
    assert len(sweeps(data)) == 3


def test_too_many_sign_changes_are_called_alternating_not_smooth():
    from spacepol.infer.residuals import ResidualReport

    def report(z):
        runs = {"m13": {"runs": 10, "expected": 20.0, "z": z, "p": 1e-6}}
        return ResidualReport(["m13"], {}, {}, runs, {}, {"m13": {}}).findings()[0]

    assert "smooth" in report(-5.0) and "alternates" not in report(-5.0)
    assert "alternates" in report(+5.0) and "smooth" not in report(+5.0)
