"""The simulated micro-polarizer camera: a uniform field of known Stokes vector comes back within
its photon-noise expectation, the analysers' extinction ratio leaks polarization as computed analytically, and the
DoLP estimator is biased and spread as the Rician distribution says."""

import numpy as np
import pytest
from scipy import stats

from spacepol.camera import linear_stokes, superpixels
from spacepol.camera.sensor import Camera, camera_from_toml
from spacepol.errors import SpacepolError

SHAPE = (256, 256)  # 16,384 superpixels


def uniform(s0, s1, s2, shape=SHAPE):
    return np.stack([np.full(shape, float(v)) for v in (s0, s1, s2)])


def estimate(camera: Camera, raw: np.ndarray) -> np.ndarray:
    """(3, H/2, W/2) Stokes photon rates: counts to photons, ideal-analyser Stokes, the analysers' transmissions out."""
    channels = {a: camera.counts_to_photons(v) for a, v in superpixels(raw, camera.layout).items()}
    s = linear_stokes(channels)
    total, diff = camera.transmissions
    return np.stack([s[0] / total, s[1] / diff, s[2] / diff])


def expected_variance(camera: Camera, stokes) -> tuple[float, float, float]:
    """Per-superpixel variances of the S0, S1, S2 estimates (photons^2 s^-2): each pixel's Poisson electrons, read
    noise and the ADC's quantisation (gain^2 / 12), in photon units, propagated through S0 = sum / 2,
    S1 = I0 - I90, S2 = I45 - I135 and the transmissions."""
    s0, s1, s2 = stokes
    total, diff = camera.transmissions
    to_photons = 1.0 / (camera.quantum_efficiency * camera.exposure_s)
    var = {}
    for theta in (0.0, 45.0, 90.0, 135.0):
        t = np.radians(theta)
        electrons = (camera.quantum_efficiency * 0.5 * (total * s0 + diff * (s1 * np.cos(2 * t) + s2 * np.sin(2 * t)))
                     + camera.dark_current_e_per_s) * camera.exposure_s
        var[theta] = (electrons + camera.read_noise_e**2 + camera.gain_e_per_dn**2 / 12) * to_photons**2
    return (0.25 * sum(var.values()) / total**2, (var[0.0] + var[90.0]) / diff**2, (var[45.0] + var[135.0]) / diff**2)


def test_a_uniform_field_comes_back_within_its_photon_noise():
    camera = Camera()
    truth = (2000.0, 300.0, -500.0)
    s = estimate(camera, camera.expose(uniform(*truth), np.random.default_rng(1)))
    n = s[0].size
    expected = expected_variance(camera, truth)
    for k in range(3):
        mean, var = s[k].mean(), s[k].var(ddof=1)
        assert abs(mean - truth[k]) < 4 * np.sqrt(expected[k] / n), (k, mean, truth[k])
        assert abs(var / expected[k] - 1) < 4 * np.sqrt(2 / (n - 1)), (k, var, expected[k])
    # the control: a sensor 10 % less efficient than declared gives S0 far outside the bound
    weaker = Camera(quantum_efficiency=0.9 * camera.quantum_efficiency)
    s_weak = estimate(camera, weaker.expose(uniform(*truth), np.random.default_rng(1)))
    assert abs(s_weak[0].mean() - truth[0]) > 20 * np.sqrt(expected[0] / n)


def test_the_extinction_ratio_leaks_polarization_as_computed():
    """Fully polarized light seen through analysers of extinction ratio ER, its Stokes computed as if they were
    ideal: DoLP (ER - 1) / (ER + 1), noise-free exactly and simulated within Monte-Carlo error."""
    for ratio in (30.0, 300.0):
        camera = Camera(extinction_ratio=ratio, dark_current_e_per_s=0.0)
        field = uniform(4000.0, 4000.0 * np.cos(0.6), 4000.0 * np.sin(0.6))
        electrons = camera.expected_electrons(field)
        ideal = linear_stokes({a: v for a, v in superpixels(electrons, camera.layout).items()})
        assert np.allclose(np.hypot(ideal[1], ideal[2]) / ideal[0], (ratio - 1) / (ratio + 1), rtol=1e-12)
        raw = camera.expose(field, np.random.default_rng(2))
        s = linear_stokes({a: camera.counts_to_photons(v) for a, v in superpixels(raw, camera.layout).items()})
        dolp = (np.hypot(s[1], s[2]) / s[0]).mean()
        assert abs(dolp - (ratio - 1) / (ratio + 1)) < 0.002, (ratio, dolp)
    assert abs(dolp - 1.0) > 0.005  # the control: an ideal analyser's DoLP 1 is not what a 300:1 grid gives


@pytest.mark.parametrize("p", [0.0, 0.03, 0.15])
def test_the_dolp_estimator_follows_the_rician_distribution(p):
    """Low light (S0 = 150 photons per superpixel): |(S1, S2)| of the estimate is Rician (nu = p S0, sigma from the
    photon noise), so DoLP = |(S1, S2)| / S0 has the mean and variance of a Rician over S0. The S0 estimate's own
    noise (relative variance c = 0.6 %) moves the mean by up to c x mean (first order) and the variance by 1-2 %:
    the mean must agree within 5 Monte-Carlo errors plus that, the variance within 5 %. At p = 0 the estimator's bias,
    sigma sqrt(pi / 2) / S0 = 0.135, is hundreds of Monte-Carlo errors: the unbiased (Gaussian) reading fails."""
    camera = Camera(read_noise_e=2.3, dark_current_e_per_s=0.0)
    s0 = 150.0
    truth = (s0, p * s0, 0.0)
    rng = np.random.default_rng(3)
    dolps = []
    for _ in range(4):
        s = estimate(camera, camera.expose(uniform(*truth), rng))
        dolps.append(np.hypot(s[1], s[2]) / s[0])
    d = np.concatenate([x.ravel() for x in dolps])
    var0, var1, var2 = expected_variance(camera, truth)
    sigma = np.sqrt(0.5 * (var1 + var2))
    rice = stats.rice(b=p * s0 / sigma, scale=sigma)
    mean, var = rice.mean() / s0, rice.var() / s0**2
    error = np.sqrt(var / d.size)
    assert abs(d.mean() - mean) < 5 * error + var0 / s0**2 * mean, (d.mean(), mean, error)
    assert abs(d.var(ddof=1) / var - 1) < 0.05, (d.var(ddof=1), var)
    if p == 0.0:
        assert abs(d.mean() - p) > 10 * error  # the control: no bias is not what the estimator does


def test_camera_settings_from_toml_are_checked(tmp_path):
    good = tmp_path / "cam.toml"
    good.write_text("[camera]\nextinction_ratio = 100\nexposure_s = 0.01\nread_noise_e = 3\n")
    camera = camera_from_toml(good)
    assert camera.extinction_ratio == 100 and camera.exposure_s == 0.01
    for text, words in (("[camera]\nexposure = 1\n", "no key exposure"), ("[camera]\nexposure_s = -1\n", "exposure_s"),
                        ("[camera]\nquantum_efficiency = 1.5\n", "quantum_efficiency"),
                        ("[camera]\nread_noise_e = '3 e'\n", "must be a number")):
        bad = tmp_path / "bad.toml"
        bad.write_text(text)
        with pytest.raises(SpacepolError, match=words):
            camera_from_toml(bad)
