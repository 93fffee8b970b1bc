"""A point source on a micro-polarizer sensor, pixel by pixel: the mean electrons of each pixel of a stamp
around the target (the sky's plus a part linear in the target's linear Stokes photon flux, through the PSF and
each analyser's transmission), and what the detectors see of it.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .detection import gaussian_psf

ANGLES_DEG = (0.0, 45.0, 90.0, 135.0)


@dataclass
class PointSourceStamp:
    """The linear model of one stamp: ``sky_e`` (H, W) and ``variance_e2`` (H, W) per pixel, ``basis`` (3, H, W)
    electrons per unit of (S0, S1, S2) in photons m^-2 s^-1, ``psf`` (H, W), ``channel`` (H, W) the index of each
    pixel's analyser in ``ANGLES_DEG``, ``full_well_e``."""

    sky_e: np.ndarray
    variance_e2: np.ndarray
    basis: np.ndarray
    psf: np.ndarray
    channel: np.ndarray
    full_well_e: float

    def electrons(self, stokes: np.ndarray) -> np.ndarray:
        """(D, H, W) the target's mean electrons for Stokes fluxes ``stokes`` (D, 3)."""
        return np.tensordot(np.atleast_2d(stokes), self.basis, axes=(1, 0))

    def saturated(self, stokes: np.ndarray) -> np.ndarray:
        """(D,) whether the brightest pixel's mean (sky and target) passes the full well."""
        return np.max(self.electrons(stokes) + self.sky_e, axis=(1, 2)) > self.full_well_e

    def deflections(self, stokes: np.ndarray, stacked: int = 1) -> dict[str, np.ndarray]:
        """{"intensity", "stokes"}: (D,) the matched filters' deflections, ``stacked`` exposures averaged."""
        s = np.atleast_2d(stokes)
        h, w = self.sky_e.shape
        per_pixel = np.einsum("ixy,jxy->ij", self.basis, self.basis / self.variance_e2)
        summed = self.basis.reshape(3, h // 2, 2, w // 2, 2).sum(axis=(2, 4))
        summed_variance = self.variance_e2.reshape(h // 2, 2, w // 2, 2).sum(axis=(1, 3))
        per_superpixel = np.einsum("ixy,jxy->ij", summed, summed / summed_variance)
        return {name: np.sqrt(np.maximum(np.einsum("di,ij,dj->d", s, m, s), 0.0) * stacked)
                for name, m in (("intensity", per_superpixel), ("stokes", per_pixel))}

    def dolp_fluxes(self, stokes: np.ndarray, stacked: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(sky (4,), sky and target (D, 4), SD (4,)) of the PSF-weighted flux per analyser channel (0, 45, 90,
        135 deg), ``stacked`` exposures averaged."""
        masks = np.stack([self.channel == c for c in range(4)])  # (4, H, W)
        weights = masks * self.psf
        sky = np.tensordot(weights, self.sky_e, axes=([1, 2], [0, 1]))
        per_stokes = np.tensordot(weights, self.basis, axes=([1, 2], [1, 2]))  # (4, 3)
        sd = np.sqrt(np.tensordot(weights**2, self.variance_e2, axes=([1, 2], [0, 1])) / stacked)
        return sky, sky + np.atleast_2d(stokes) @ per_stokes.T, sd


def point_source_stamp(camera, sky_stokes: np.ndarray, centre: tuple[float, float], size_pixels: int = 18,
                       psf: np.ndarray | None = None) -> PointSourceStamp:
    """The stamp of ``size_pixels`` (even) on a side for ``camera`` under a uniform sky of Stokes photon rate
    ``sky_stokes`` (3,) per pixel (photons s^-1 before the analysers) with the target's PSF centred at ``centre``
    (row, column in pixels): the camera's Gaussian, or ``psf`` (size_pixels, size_pixels; sum 1) as given."""
    shape = (size_pixels, size_pixels)
    sky_e = camera.expected_electrons(np.stack([np.full(shape, v) for v in sky_stokes]))
    variance = sky_e + camera.read_noise_e**2
    psf = gaussian_psf(size_pixels, camera.psf_fwhm_pixels, centre) if psf is None else np.asarray(psf, float)
    theta = np.radians(camera.angle_map(shape))
    total, diff = camera.transmissions
    scale = 0.5 * camera.quantum_efficiency * camera.exposure_s * camera.transmittance * camera.aperture_area_m2
    basis = scale * psf * np.stack([np.full(shape, total), diff * np.cos(2 * theta), diff * np.sin(2 * theta)])
    channel = np.searchsorted(np.array(ANGLES_DEG), camera.angle_map(shape))
    return PointSourceStamp(sky_e, variance, basis, psf, channel, camera.full_well_e)


def superpixel_positions(size_pixels: int = 18, per_side: int = 4) -> list[tuple[float, float]]:
    """``per_side``^2 target centres (row, column) spread evenly over the superpixel nearest the stamp's centre."""
    corner = 2 * (size_pixels // 4) - 0.5  # the outer edge of that superpixel, in pixel coordinates
    steps = corner + 2.0 * (np.arange(per_side) + 0.5) / per_side
    return [(float(r), float(c)) for r in steps for c in steps]
