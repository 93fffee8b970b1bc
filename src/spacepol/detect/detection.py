"""Detecting a point source in micro-polarizer frames at a fixed false-alarm rate: the matched filter (the
likelihood-ratio test under Gaussian noise of the sky, dark current and read noise) per detector (intensity, Stokes,
DoLP image), and its Neyman-Pearson curve P_d = Q(Q^-1(P_fa) - d), d the filter's output SNR.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import numpy as np
from scipy import stats

from ..camera.mosaic import dolp, linear_stokes

DETECTORS = ("intensity", "stokes", "dolp")
SKY_CHUNK = 200_000  # sky-only draws held at once by the DoLP detector's threshold


def gaussian_psf(size: int, fwhm_pixels: float, centre: tuple[float, float] | None = None) -> np.ndarray:
    """(size, size) PSF normalised to sum 1: a circular Gaussian of the FWHM given, centred on the stamp."""
    sigma = fwhm_pixels / (2 * np.sqrt(2 * np.log(2)))
    cy, cx = centre if centre is not None else ((size - 1) / 2, (size - 1) / 2)
    y, x = np.mgrid[0:size, 0:size]
    psf = np.exp(-((x - cx) ** 2 + (y - cy) ** 2) / (2 * sigma**2))
    return psf / psf.sum()


def neyman_pearson(deflection, p_false_alarm: float):
    """P_d = Q(Q^-1(P_fa) - d) of a matched filter with deflection d in Gaussian noise."""
    return stats.norm.sf(stats.norm.isf(p_false_alarm) - np.asarray(deflection, float))


def _per_pixel(variance, signal: np.ndarray) -> np.ndarray:
    """The noise variance (4,) per channel or (4, H, W) per channel pixel, as (4, H, W)."""
    return np.broadcast_to(np.asarray(variance, float).reshape(4, *([1] * (signal.ndim - 1))), signal.shape)


def deflections(signal: np.ndarray, variance: np.ndarray) -> dict[str, float]:
    """{detector: d} of the intensity and Stokes matched filters for the target's electrons ``signal`` (4, H, W) per
    analyser channel and the noise ``variance`` (4,) or (4, H, W) per channel pixel."""
    signal = np.asarray(signal, float)
    variance = _per_pixel(variance, signal)
    total = signal.sum(axis=0)
    return {"intensity": float(np.sum(total**2 / variance.sum(axis=0)) ** 0.5),
            "stokes": float(np.sum(signal**2 / variance) ** 0.5)}


def matched_filter(frames: np.ndarray, background: np.ndarray, signal: np.ndarray, variance: np.ndarray,
                   detector: str) -> np.ndarray:
    """The whitened matched-filter statistic of each frame (N, 4, H, W) for the known ``signal`` (4, H, W) over the
    known ``background`` (4,) per channel pixel; normalised to unit variance, so the mean with the target is d."""
    frames = np.asarray(frames, float) - np.asarray(background, float).reshape(1, 4, 1, 1)
    var = _per_pixel(variance, signal)
    if detector == "intensity":
        summed, s, v = frames.sum(axis=1), signal.sum(axis=0), var.sum(axis=0)
        return np.tensordot(summed, s / v, axes=([1, 2], [0, 1])) / np.sqrt(np.sum(s**2 / v))
    if detector == "stokes":
        return np.tensordot(frames, signal / var, axes=([1, 2, 3], [0, 1, 2])) / np.sqrt(np.sum(signal**2 / var))
    raise ValueError(f"detector '{detector}': the matched filters are intensity and stokes")


def dolp_statistic(frames: np.ndarray, background: np.ndarray, psf: np.ndarray) -> np.ndarray:
    """|DoLP - the sky's DoLP| of the PSF-weighted flux of each frame (N, 4, H, W) over a sky of ``background`` (4,)
    electrons per channel pixel (analysers 0, 45, 90, 135 deg in the channel order): the DoLP image's detector."""
    flux = np.tensordot(np.asarray(frames, float), psf, axes=([2, 3], [0, 1]))
    return dolp_contrast(flux, np.asarray(background, float) * psf.sum())


def _dolp(flux: np.ndarray) -> np.ndarray:
    return dolp(linear_stokes(dict(zip((0.0, 45.0, 90.0, 135.0), np.moveaxis(np.asarray(flux, float), -1, 0)))))


def dolp_contrast(flux: np.ndarray, sky_flux: np.ndarray) -> np.ndarray:
    """|DoLP(flux) - DoLP(sky_flux)| of channel fluxes (..., 4) against the sky's own (4,)."""
    return np.abs(_dolp(flux) - _dolp(sky_flux))


def dolp_detection_probability(sky_flux: np.ndarray, target_flux: np.ndarray, flux_sd: np.ndarray, p_false_alarm: float,
                               rng: np.random.Generator, sky_frames: int | None = None, target_frames: int = 2000) -> np.ndarray:
    """(D,) P_d of the DoLP detector from its PSF-weighted channel fluxes F_c (analysers 0, 45, 90, 135 deg): their
    means on the sky alone ``sky_flux`` (4,) and with each target ``target_flux`` (D, 4), and their noise SD
    ``flux_sd`` (4,). With Gaussian pixel noise the F_c are Gaussian, so they are drawn directly: ``sky_frames``
    sky-only ones (default 20 / P_fa) set the threshold, ``target_frames`` per target give its P_d (binomial error
    at most 0.5 / sqrt(target_frames))."""
    sky_flux, flux_sd = np.asarray(sky_flux, float), np.asarray(flux_sd, float)
    target_flux = np.atleast_2d(np.asarray(target_flux, float))
    sky_frames = int(np.ceil(20 / p_false_alarm)) if sky_frames is None else sky_frames
    if sky_frames <= SKY_CHUNK:
        threshold = threshold_from_sky(dolp_contrast(sky_flux + flux_sd * rng.standard_normal((sky_frames, 4)), sky_flux),
                                       p_false_alarm)
    else:  # a small P_fa: the sky-only draws in chunks, keeping only the largest statistics the quantile needs
        keep = int(np.ceil(sky_frames * p_false_alarm)) + 2
        top = np.empty(0)
        for first in range(0, sky_frames, SKY_CHUNK):
            count = min(SKY_CHUNK, sky_frames - first)
            chunk = dolp_contrast(sky_flux + flux_sd * rng.standard_normal((count, 4)), sky_flux)
            top = np.partition(np.concatenate([top, chunk]), -keep)[-keep:] if top.size + count > keep else \
                np.concatenate([top, chunk])
        # numpy's linear quantile at 1 - P_fa over all sky_frames statistics, from the largest ones alone
        position = (1.0 - p_false_alarm) * (sky_frames - 1) - (sky_frames - keep)
        ordered = np.sort(top)
        low = int(np.floor(position))
        threshold = float(ordered[low] + (position - low) * (ordered[min(low + 1, keep - 1)] - ordered[low]))
    frames = target_flux[:, None, :] + flux_sd * rng.standard_normal((len(target_flux), target_frames, 4))
    return np.mean(dolp_contrast(frames, sky_flux) > threshold, axis=1)


def threshold_from_sky(sky_statistics: np.ndarray, p_false_alarm: float) -> float:
    """The threshold that sky-only statistics exceed with probability ``p_false_alarm`` (their upper quantile); at
    least 10 / P_fa of them are needed for a quantile worth the name."""
    sky_statistics = np.ravel(sky_statistics)
    if sky_statistics.size * p_false_alarm < 10:
        raise ValueError(f"{sky_statistics.size} sky-only statistics set no threshold at P_fa {p_false_alarm:g} "
                         f"(need at least {int(np.ceil(10 / p_false_alarm))})")
    return float(np.quantile(sky_statistics, 1.0 - p_false_alarm))


def detection_probability(target_statistics: np.ndarray, threshold: float) -> tuple[float, float]:
    """(P_d, its binomial standard error) of the statistics with the target over ``threshold``."""
    hits = np.ravel(target_statistics) > threshold
    p = float(hits.mean())
    return p, float(np.sqrt(max(p * (1 - p), 1.0 / hits.size) / hits.size))
