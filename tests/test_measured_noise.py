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


def _grazing_noise_render(grow: float, seed: int):
    """``specular+subsurface`` at NIST's PTFE geometries at 0.633 um (their reciprocal and mirror pairs), each
    normalised element with noise 0.01 below 50 deg of exit, rising by ``grow`` x 0.01 at 90 deg: the measured noise
    grows towards grazing exit, as PTFE's does. (data, each row's noise)."""
    from spacepol.io.measurements import read_measurements
    from spacepol.paths import bundled

    g = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv")).at_wavelength(0.633).geometry
    m = np.asarray(Model.from_string("specular+subsurface").evaluate(TRUTH, g, mueller=True).mueller)
    sd = 0.01 * (1 + grow * np.clip((np.abs(np.asarray(g.theta_r)) - 50.0) / 40.0, 0, 1))
    normalised = m / m[0, 0] + sd * np.random.default_rng(seed).standard_normal(m.shape)
    normalised[0, 0] = 1.0
    data = Dataset(g.theta_i, g.theta_r, g.dphi, wavelength_um=np.full(g.size, 0.633))
    data.mueller, data.brdf = normalised * m[0, 0], m[0, 0]
    data.source = "render"
    return data, sd


def _levels_at_truth(grow: float) -> dict:
    """{group: (level with the mirror pairs' profile, one level for all rows)} at the truth, each over the noise
    where the reciprocal pairs lie, for the render ``_grazing_noise_render(grow)``."""
    from spacepol.criticism.reciprocity import PROFILE_EDGES_DEG, mirror_scatter

    data, sd = _grazing_noise_render(grow, seed=1)
    at_pairs = sd[np.unique(reciprocal_pairs(data))].mean()
    model = Model.from_string("specular+subsurface")
    params = {k: np.array([v]) for k, v in TRUTH.items()}
    levels = tuple((name, 1e-6, 1.0) for name in GROUPS)
    flat = Likelihood(data, model, observables=["mueller"]).profiled(params, levels)[1]
    data.mueller_noise_profile = mirror_scatter(data, PROFILE_EDGES_DEG).noise_profile(data)
    shaped = Likelihood(data, model, observables=["mueller"]).profiled(params, levels)[1]
    out = {name: (float(shaped[name][0]) / at_pairs, float(flat[name][0]) / at_pairs) for name in GROUPS}
    print(f"noise rising {grow:g} x towards grazing: (profiled, one level) / noise at the reciprocal pairs {out}")
    return out


def test_a_noise_profile_from_the_mirror_pairs_makes_the_inferred_level_the_reciprocal_pairs_noise():
    """Noise growing 4x towards grazing exit: the profile the mirror pairs give (``MirrorScatter.noise_profile``) makes
    each group's profiled noise level at the truth the noise where the reciprocal pairs lie (within 15 %: each 10-deg
    bin's spread rests on ~500 mirror differences, ~3 % each, and the level on the two bins of the reciprocal pairs);
    one level for all rows overstates it by more than 30 %. Control: with noise the same everywhere the profile
    changes the level by less than 15 % (the same bins set it)."""
    for name, (shaped, flat) in _levels_at_truth(3.0).items():
        assert abs(shaped - 1) < 0.15 and flat > 1.3, (name, shaped, flat)
    for name, (shaped, flat) in _levels_at_truth(0.0).items():
        assert abs(shaped / flat - 1) < 0.15, (name, shaped, flat)


def test_a_noise_profile_of_the_wrong_shape_or_sign_is_one_error_naming_it():
    from spacepol.errors import ParameterError

    data, _ = _grazing_noise_render(0.0, seed=1)
    model = Model.from_string("specular+subsurface")
    for bad, words in [(np.ones((2, len(data))), "shape (2,"), (-np.ones((3, len(data))), "values <= 0")]:
        data.mueller_noise_profile = bad
        with pytest.raises(ParameterError, match="mueller_noise_profile") as error:
            Likelihood(data, model, observables=["mueller"])
        assert words in str(error.value), str(error.value)


def test_pair_differences_are_measured_in_units_of_the_level_where_the_noise_profile_is_one():
    """A grid of geometries that holds each one's reciprocal, with a noise profile of 1 on rows lit at less than 40 deg
    and 3 beyond (each element's noise 0.01 x the profile): a pair across the step has a difference of
    sqrt(1 + 9) x 0.01. Divided by the profile at its two members, the differences measure the level the likelihood
    multiplies by the profile, 0.01 (within 4 SE of the median's Monte-Carlo error); control: without the profile the
    same data measure more than 1.5x that."""
    from spacepol.physics.geometry import Geometry

    angles = np.arange(10.0, 71.0, 10.0)
    ti, tr, dphi = (a.ravel() for a in np.meshgrid(angles, angles, [-150.0, -90.0, -30.0, 30.0, 90.0, 150.0, 180.0]))
    g = Geometry(ti, tr, dphi)
    m = np.asarray(Model.from_string("specular+subsurface").evaluate(TRUTH, g, mueller=True).mueller)
    profile = np.where(ti < 40.0, 1.0, 3.0)
    normalised = m / m[0, 0] + 0.01 * profile * np.random.default_rng(4).standard_normal(m.shape)
    normalised[0, 0] = 1.0
    data = Dataset(ti, tr, dphi, wavelength_um=np.full(g.size, 0.633))
    data.mueller, data.brdf, data.source = normalised * m[0, 0], m[0, 0], "render"
    pairs = reciprocal_pairs(data)
    assert np.mean(profile[pairs[:, 0]] != profile[pairs[:, 1]]) > 0.3, "the control needs pairs across the step"
    flat = measure(Likelihood(data, Model.from_string("specular+subsurface"), observables=["mueller"]))
    data.mueller_noise_profile = np.tile(profile, (3, 1))
    shaped = measure(Likelihood(data, Model.from_string("specular+subsurface"), observables=["mueller"]))
    for name in GROUPS:
        got, se = shaped[name].value / 0.01, shaped[name].standard_error / 0.01
        assert abs(got - 1) < 4 * se, f"{name}: {got:.3f} +- {se:.3f} of the level; margin {(4 * se - abs(got - 1)) / se:.1f} SE"
        assert flat[name].value / 0.01 > 1.5, (name, flat[name].value)
        print(f"{name}: {got:.3f} +- {se:.3f} of the level with the profile, {flat[name].value / 0.01:.3f} without")
