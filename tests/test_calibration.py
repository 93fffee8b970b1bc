"""Simulation-based calibration (``spacepol.infer.calibration``): the statistics on known ranks, emcee calibrated
on a small problem (fast), its negative control (a likelihood told the noise is 3x smaller than it is must fail),
and every sampling engine over 100 replicates (slow; ``benchmarks/sbc_engines.py`` prints the figures)."""

import numpy as np
import pytest

import spacepol
from spacepol.infer.calibration import LEVELS, Calibration
from spacepol.physics.geometry import Geometry
from spacepol.priors import Fixed, Uniform

PRIORS = {"n": Uniform(1.2, 2.0), "sigma": Uniform(0.1, 0.4), "k": Fixed(0.0), "ks": Fixed(1.0)}
MODEL = "specular+smith"


def _geometry():
    theta_i = np.repeat([25.0, 55.0], 6)
    return Geometry(theta_i, np.tile(np.linspace(5, 75, 6), 2), np.full(theta_i.size, 180.0))


def _calibrate(engine, replicates, seed, scale=1.0, **options):
    return spacepol.calibrate(MODEL, PRIORS, _geometry(), engine=engine, replicates=replicates, seed=seed,
                              engine_options=options, noise_dop=0.02, noise_brdf=0.1, likelihood_noise_scale=scale)


def _record(ranks, inside):
    """A Calibration of known ranks (no sampling): ``inside`` per level from the ranks' own quantile."""
    ranks = np.asarray(ranks)
    return Calibration(engine="known", names=("a", "b"), truths=np.zeros_like(ranks, float), ranks=ranks,
                       inside={level: inside(ranks, level) for level in LEVELS})


def _central(ranks, level):
    u = ranks / 99.0
    return (u >= (1 - level) / 2) & (u <= (1 + level) / 2)


def test_the_statistics_pass_uniform_ranks_and_fail_too_narrow_or_biased_ones():
    """Uniform ranks (a calibrated engine) pass; a too narrow engine (ranks at both ends: the truth too often outside
    its draws) and a biased one (ranks tilted) fail on the coverage or the histogram."""
    rng = np.random.default_rng(0)
    uniform = _record(rng.integers(0, 100, (400, 2)), _central)
    assert uniform.calibrated, uniform.failures()
    assert abs(uniform.coverage(0.9)[0] - 0.9) < 0.05
    u = rng.uniform(size=(400, 2))
    narrow = _record(np.round(99 * np.where(u < 0.5, u**3 * 4, 1 - (1 - u) ** 3 * 4)).clip(0, 99), _central)
    assert not narrow.calibrated and any("intervals hold the truth" in f for f in narrow.failures())
    biased = _record(np.round(99 * rng.uniform(size=(400, 2)) ** 1.6), _central)
    assert any("ranks not uniform" in f for f in biased.failures()), biased.failures()
    assert uniform.figure().axes and uniform.to_json()["calibrated"] is True


def test_emcee_is_calibrated_on_a_small_problem():
    """Fast version (8 replicates; the 100-replicate check is slow): the 50 % and 90 % intervals hold the truth within their binomial bands and the
    ranks are uniform."""
    c = _calibrate("emcee", 8, seed=101, max_steps=1000, tau_multiple=20)
    assert c.replicates == 8 and c.refused == 0
    assert c.calibrated, c.failures()


def test_emcee_with_a_wrong_noise_in_the_likelihood_fails_calibration():
    """Negative control: the same data, the likelihood told the noise is 3x smaller than it is."""
    c = _calibrate("emcee", 8, seed=101, scale=1 / 3, max_steps=1000, tau_multiple=20)
    assert not c.calibrated
    lo, _ = c.coverage_band(0.9)
    assert np.any(c.coverage(0.9) < lo), c.coverage(0.9)


SLOW_OPTIONS = {
    "emcee": {"max_steps": 3000},
    "laplace": {},
    "nested": {"live": 100, "replicates": 1, "effective_draws": 500},
    "nuts": {"chains": 2, "warmup": 200, "draws": 250, "max_draws": 250},
}


@pytest.mark.slow
@pytest.mark.parametrize("engine", sorted(SLOW_OPTIONS))
def test_every_sampling_engine_is_calibrated_over_100_replicates_and_its_negative_control_fails(engine):
    """Acceptance: 100 replicates per engine; 30 with the wrong noise must fail."""
    c = _calibrate(engine, 100, seed=2026, **SLOW_OPTIONS[engine])
    print(engine, c.to_json()["parameters"])
    assert c.replicates >= 95 and c.calibrated, c.failures()
    control = _calibrate(engine, 30, seed=2026, scale=1 / 3, **SLOW_OPTIONS[engine])
    assert not control.calibrated


def _ridge_calibration(replicates, seed, scale=1.0):
    """SBC of diagnose's default posterior on a metal's curved n-k band (``benchmarks/sbc_ridge.py``'s problem)."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    from sbc_ridge import calibrate

    return calibrate(replicates, seed, scale)


def test_diagnoses_posterior_is_calibrated_on_a_curved_band():
    """Fast version (8 replicates; 100 and the negative control are slow): Laplace-IS where its checks trust it, emcee
    elsewhere, and the intervals hold the truth within their binomial bands."""
    c, ran = _ridge_calibration(8, seed=2027)
    assert c.replicates == 8 and sum(ran.values()) == 8
    assert c.calibrated, (c.failures(), ran)


@pytest.mark.slow
def test_diagnoses_posterior_is_calibrated_on_a_curved_band_over_100_replicates_and_its_control_fails():
    """Acceptance: 100 replicates; 30 with the likelihood told the noise is 3x smaller must fail."""
    c, ran = _ridge_calibration(100, seed=2027)
    print(ran, c.to_json()["parameters"])
    assert c.replicates == 100 and c.calibrated, c.failures()
    control, _ = _ridge_calibration(30, seed=2027, scale=1 / 3)
    assert not control.calibrated
