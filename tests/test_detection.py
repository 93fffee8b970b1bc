"""Detection at a fixed false-alarm rate: thresholds set from sky-only frames, P_d of a point
source of known deflection against the Neyman-Pearson curve of each matched filter, a wrong threshold caught, and
the DoLP detector's false-alarm rate held on independent sky frames."""

import numpy as np
import pytest

from spacepol.detect.detection import (deflections, detection_probability, dolp_statistic, gaussian_psf, matched_filter,
                                       neyman_pearson, threshold_from_sky)

P_FA = 1e-3
ANGLES = np.radians([0.0, 45.0, 90.0, 135.0])
SIZE = 9  # superpixels on a side


def channels(total: float, dolp: float, aop_deg: float) -> np.ndarray:
    """(4,) share of ``total`` behind ideal analysers at 0, 45, 90, 135 deg."""
    return 0.5 * total * (1 + dolp * np.cos(2 * (ANGLES - np.radians(aop_deg))))


def scene(target_e: float):
    """A bright, strongly polarized sky (DoLP 0.6 at 30 deg, 4,000 e per channel pixel on average) and a target of
    ``target_e`` electrons polarized 0.3 at 120 deg (crossed with the sky's): background (4,), signal (4, H, W),
    variance (4,) (Poisson + 5 e read noise)."""
    background = channels(8000.0, 0.6, 30.0)
    psf = gaussian_psf(SIZE, 2.0)
    signal = channels(target_e, 0.3, 120.0)[:, None, None] * psf
    return background, signal, background + 25.0, psf


def frames(background, signal, count, rng):
    """``count`` frames (count, 4, H, W): Poisson electrons plus Gaussian read noise."""
    mean = np.broadcast_to(background.reshape(4, 1, 1) + signal, (count, 4, SIZE, SIZE))
    return rng.poisson(mean).astype(float) + 5.0 * rng.standard_normal(mean.shape)


@pytest.mark.parametrize("detector", ["intensity", "stokes"])
def test_pd_at_a_fixed_false_alarm_rate_follows_the_neyman_pearson_curve(detector):
    """The threshold from 100,000 sky-only frames at P_fa = 1e-3; P_d from 20,000 frames with the target against
    Q(Q^-1(P_fa) - d). The Monte-Carlo error holds the binomial error of P_d and the threshold's quantile error
    (sd of the 1e-3 quantile of 1e5 draws: sqrt(p / n) / phi(z) = 0.03 in units of the statistic's sd). The
    control: the threshold of P_fa = 1e-2 on the same statistics misses the curve."""
    rng = np.random.default_rng(7)
    background, signal, variance, _ = scene(target_e=1.0)
    d_unit = deflections(signal, variance)[detector]
    background, signal, variance, _ = scene(target_e=3.2 / d_unit)  # d = 3.2: P_d about 0.55
    d = deflections(signal, variance)[detector]
    sky = np.concatenate([matched_filter(frames(background, 0 * signal, 20_000, rng), background, signal, variance, detector)
                          for _ in range(5)])
    target = matched_filter(frames(background, signal, 20_000, rng), background, signal, variance, detector)
    threshold = threshold_from_sky(sky, P_FA)
    p_d, binomial = detection_probability(target, threshold)
    expected = neyman_pearson(d, P_FA)
    z = 3.0902  # Q^-1(1e-3)
    quantile_sd = np.sqrt(P_FA / sky.size) / (np.exp(-z**2 / 2) / np.sqrt(2 * np.pi))
    error = np.hypot(binomial, quantile_sd * np.exp(-(z - d) ** 2 / 2) / np.sqrt(2 * np.pi))
    assert abs(p_d - expected) < 4 * error, (p_d, expected, error)
    wrong, _ = detection_probability(target, threshold_from_sky(sky, 1e-2))
    assert abs(wrong - expected) > 4 * error


def test_the_stokes_detector_beats_intensity_only_when_polarization_differs():
    background, signal, variance, _ = scene(target_e=1000.0)
    d = deflections(signal, variance)
    assert d["stokes"] > 1.2 * d["intensity"]  # the crossed target against a bright polarized sky
    unpolarized_sky = channels(8000.0, 0.0, 0.0) + 25.0
    same = channels(1000.0, 0.0, 0.0)[:, None, None] * gaussian_psf(SIZE, 2.0)
    d_same = deflections(same, unpolarized_sky)
    assert d_same["stokes"] == pytest.approx(d_same["intensity"], rel=1e-9)  # nothing to gain: equal (Cauchy-Schwarz)


def test_the_dolp_detectors_threshold_from_sky_frames_holds_its_false_alarm_rate():
    """No closed form: its threshold from 50,000 sky-only frames gives, on 50,000 independent ones, a false-alarm
    rate within the binomial error of 1e-3 (about 3 sigma: 0.55 to 1.45 x 1e-3, with the threshold's own
    quantile error)."""
    rng = np.random.default_rng(11)
    background, signal, variance, psf = scene(target_e=3000.0)
    sky = np.concatenate([dolp_statistic(frames(background, 0 * signal, 10_000, rng), background, psf) for _ in range(5)])
    threshold = threshold_from_sky(sky, P_FA)
    fresh = np.concatenate([dolp_statistic(frames(background, 0 * signal, 10_000, rng), background, psf) for _ in range(5)])
    rate, _ = detection_probability(fresh, threshold)
    assert 0.45 * P_FA < rate < 1.55 * P_FA, rate
    with pytest.raises(ValueError, match="set no threshold"):
        threshold_from_sky(sky[:5000], P_FA)


def channel_fluxes(totals, background, variance, psf, stacked):
    """The PSF-weighted channel fluxes' sky mean, mean with the target and SD for this stamp of superpixels: the
    target's ``totals`` (4,) electrons per channel spread by ``psf`` over the channel's pixels."""
    w1, w2 = psf.sum(), np.sum(psf**2)
    return background * w1, (background * w1 + totals * w2)[None, :], np.sqrt(variance * w2 / stacked)


def test_the_dolp_detectors_pd_from_channel_fluxes_equals_full_frames_and_stacking():
    """Over a pass the DoLP detector's P_d comes from the four PSF-weighted channel fluxes drawn directly
    (``dolp_detection_probability``). Full Poisson frames with read noise, the threshold from 20,000 sky-only frames
    and P_d from 4,000 with the target, give the same P_d within Monte-Carlo error, for one exposure and for four
    averaged. The control: the one-exposure figure against the four averaged frames misses."""
    from spacepol.detect.detection import dolp_detection_probability

    rng = np.random.default_rng(5)
    background, signal, variance, psf = scene(target_e=1.0)
    totals = signal.sum(axis=(1, 2))  # (4,) electrons per channel for 1 e in all: the PSF sums to 1
    measured, reduced = {}, {}
    for stacked in (1, 4):
        target_e = 900.0 / stacked**0.5  # P_d about one half
        sky = np.concatenate([dolp_statistic(np.mean([frames(background, 0 * signal, 5000, rng) for _ in range(stacked)], axis=0),
                                             background, psf) for _ in range(4)])
        hits = np.mean([frames(background, target_e * signal, 4000, rng) for _ in range(stacked)], axis=0)
        p_full, error_full = detection_probability(dolp_statistic(hits, background, psf), threshold_from_sky(sky, 1e-3))
        p_fast = dolp_detection_probability(*channel_fluxes(target_e * totals, background, variance, psf, stacked), 1e-3, rng,
                                            target_frames=20_000)[0]
        measured[stacked], reduced[stacked] = (p_full, error_full), p_fast
        # binomial errors of both P_d plus the two thresholds' quantile errors (about 0.02 each at P_d 1/2)
        assert 0.2 < p_full < 0.9 and abs(p_fast - p_full) < 4 * np.hypot(error_full, 0.03), (stacked, p_full, p_fast)
    single_against_stack = dolp_detection_probability(*channel_fluxes(900.0 / 2 * totals, background, variance, psf, 1),
                                                      1e-3, rng, target_frames=20_000)[0]
    p_full, error_full = measured[4]
    assert abs(single_against_stack - p_full) > 4 * np.hypot(error_full, 0.03)


def test_the_dolp_threshold_from_sky_draws_in_chunks_is_the_quantile_of_all_of_them(monkeypatch):
    """A small P_fa needs 20 / P_fa sky-only draws: drawn in chunks, keeping only the largest statistics, the
    threshold (and so P_d) is exactly the one from all the draws at once (the same random numbers)."""
    import spacepol.detect.detection as detection

    sky, sd = np.array([1000.0, 800.0, 600.0, 800.0]), np.full(4, 30.0)
    target = sky[None, :] + np.array([[40.0, 0.0, -40.0, 0.0], [10.0, 0.0, -10.0, 0.0]])
    whole = detection.dolp_detection_probability(sky, target, sd, 1e-3, np.random.default_rng(1), sky_frames=50_000,
                                                 target_frames=4000)
    monkeypatch.setattr(detection, "SKY_CHUNK", 7000)
    chunked = detection.dolp_detection_probability(sky, target, sd, 1e-3, np.random.default_rng(1), sky_frames=50_000,
                                                   target_frames=4000)
    assert np.array_equal(whole, chunked) and whole[0] > whole[1] > 0.0
