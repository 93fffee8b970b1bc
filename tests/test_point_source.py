"""The pass's detection figures against simulated raw frames: the pixel-level linear model of a point
source on the micro-polarizer mosaic (``detect.point_source``) predicts the P_d that frames simulated by the camera
(Poisson electrons, read noise, the ADC) show, for a target at a random place within a superpixel, for the intensity
and Stokes matched filters and the DoLP image. The control: the figure for a target always centred on a superpixel,
which the pass used before, misses."""

import numpy as np
import pytest

from spacepol.camera.sensor import Camera
from spacepol.detect.detection import (detection_probability, dolp_contrast, dolp_detection_probability, neyman_pearson,
                                       threshold_from_sky)
from spacepol.detect.point_source import ANGLES_DEG, point_source_stamp, superpixel_positions

P_FA = 1e-2
SIZE = 18
CAMERA = Camera(exposure_s=2e-3)
SKY = np.array([4e5, 4e5 * 0.5 * np.cos(np.radians(60)), 4e5 * 0.5 * np.sin(np.radians(60))])  # photons s^-1 per pixel


def raw_frames(stokes, centres, rng):
    """Frames (N, H, W) in electrons (counts back through the gain) of the sky plus the target at each centre."""
    from spacepol.detect.detection import gaussian_psf

    area = CAMERA.transmittance * CAMERA.aperture_area_m2
    out = []
    for centre in centres:
        field = np.stack([np.full((SIZE, SIZE), v) for v in SKY])
        if centre is not None:
            field = field + np.asarray(stokes)[:, None, None] * gaussian_psf(SIZE, CAMERA.psf_fwhm_pixels, centre) * area
        out.append((CAMERA.expose(field, rng) + 0.5) * CAMERA.gain_e_per_dn)
    return np.array(out)


def statistics(frames, stamp, stokes):
    """Each frame's intensity and Stokes matched-filter outputs (unit variance) and its DoLP-image statistic."""
    residual = frames - stamp.sky_e
    signal = stamp.electrons(stokes)[0]
    h, w = signal.shape
    summed = residual.reshape(-1, h // 2, 2, w // 2, 2).sum(axis=(2, 4))
    s_sum = signal.reshape(h // 2, 2, w // 2, 2).sum(axis=(1, 3))
    v_sum = stamp.variance_e2.reshape(h // 2, 2, w // 2, 2).sum(axis=(1, 3))
    intensity = np.tensordot(summed, s_sum / v_sum, axes=([1, 2], [0, 1])) / np.sqrt(np.sum(s_sum**2 / v_sum))
    stokes_filter = np.tensordot(residual, signal / stamp.variance_e2, axes=([1, 2], [0, 1])) \
        / np.sqrt(np.sum(signal**2 / stamp.variance_e2))
    weights = np.stack([(stamp.channel == c) * stamp.psf for c in range(len(ANGLES_DEG))])
    fluxes = np.tensordot(frames, weights, axes=([1, 2], [1, 2]))
    sky_flux = np.tensordot(weights, stamp.sky_e, axes=([1, 2], [0, 1]))
    return {"intensity": intensity, "stokes": stokes_filter, "dolp": dolp_contrast(fluxes, sky_flux)}


FLUX = {"intensity": 1.3e5, "stokes": 9.0e4, "dolp": 3.0e5}  # photons m^-2 s^-1 in S0: P_d about one half each


@pytest.fixture(scope="module")
def measured():
    """Per detector, P_d measured on 3,040 frames with the target (polarized 0.5 across the sky's 60 deg) at a
    random one of 16 places over a superpixel (thresholds from 3,000 sky-only frames per place), the model's
    prediction averaged over the places, and the figure for a target centred on a superpixel."""
    rng = np.random.default_rng(21)
    places = superpixel_positions(SIZE, 4)
    hits = {k: [] for k in FLUX}
    predicted = {k: [] for k in FLUX}
    for place in places:
        stamp = point_source_stamp(CAMERA, SKY, place, SIZE)
        unit = np.array([[1.0, -0.5, 0.0]])
        sky = statistics(raw_frames(None, [None] * 3000, rng), stamp, unit)  # matched filters scale-free in the flux
        for k, flux in FLUX.items():
            stokes = flux * unit
            assert not stamp.saturated(stokes)[0]
            target = statistics(raw_frames(stokes[0], [place] * 190, rng), stamp, stokes)[k]
            hits[k].append(target > threshold_from_sky(sky[k], P_FA))
            if k == "dolp":
                predicted[k].append(float(dolp_detection_probability(*stamp.dolp_fluxes(stokes), P_FA, rng, target_frames=4000)[0]))
            else:
                predicted[k].append(float(neyman_pearson(stamp.deflections(stokes)[k][0], P_FA)))
    middle = point_source_stamp(CAMERA, SKY, superpixel_positions(SIZE, 1)[0], SIZE)  # a superpixel's centre
    centred = {k: float(neyman_pearson(middle.deflections(FLUX[k] * np.array([[1.0, -0.5, 0.0]]))[k][0], P_FA))
               for k in ("intensity", "stokes")}
    return ({k: np.concatenate(v) for k, v in hits.items()}, {k: float(np.mean(v)) for k, v in predicted.items()},
            centred)


@pytest.mark.parametrize("detector", ["intensity", "stokes", "dolp"])
def test_frames_show_the_pd_the_point_source_model_predicts(measured, detector):
    hits, predicted, _ = measured
    p_d, binomial = detection_probability(hits[detector], 0.5)
    # the thresholds' own quantile error (3,000 sky frames at P_fa 1e-2: about 0.1 SD of the statistic) moves P_d by
    # up to 0.04 at P_d 1/2; with 16 independent thresholds averaged it is about 0.01
    error = np.hypot(binomial, 0.012)
    assert 0.15 < p_d < 0.95, p_d  # a test on the slope of the curve, not on a flat end
    assert abs(p_d - predicted[detector]) < 4 * error, (detector, p_d, predicted[detector], error)


def test_a_target_always_centred_on_a_superpixel_is_the_wrong_figure(measured):
    hits, predicted, centred = measured
    p_d, binomial = detection_probability(hits["intensity"], 0.5)  # the Stokes filter gains from any place alike
    assert abs(centred["intensity"] - p_d) > 4 * np.hypot(binomial, 0.012), (centred["intensity"], p_d)
