"""Simulated micro-polarizer frames of the target on the sky: the raw mosaic of one exposure around the target (the
sky's electrons per analyser pixel, the target's through the PSF, photon and read noise, the ADC), and its S0 and
DoLP images (superpixel demosaicking), for the observe report's montage."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ..camera.mosaic import stokes_maps
from .detection import gaussian_psf
from .observation import sky_stokes_per_pixel


def frame_field(observation, time_index: int, draw_index: int | None, superpixels: int = 24) -> np.ndarray:
    """(3, 2 n, 2 n) the Stokes photon rate (photons s^-1 per pixel, before the analysers) of the stamp around the
    target at ``time_index``: the uniform sky plus, unless ``draw_index`` is None, the target of that material draw
    through the PSF at the stamp's centre."""
    camera, n = observation.camera, superpixels
    j = time_index
    sky = sky_stokes_per_pixel(camera, observation.sky_photons_arcsec2[j], observation.sky_dolp[j], observation.sky_aop_deg[j])
    field = np.stack([np.full((2 * n, 2 * n), v) for v in sky])
    if draw_index is None:
        return field
    s = observation.light.stokes_w_m2[:, draw_index, time_index] * observation.light.photons_per_joule
    if np.all(np.isfinite(s)) and s[0] > 0:
        psf = gaussian_psf(2 * n, camera.psf_fwhm_pixels)  # on the pixel grid, sum 1
        field = field + np.stack([s[k] * psf for k in range(3)]) * camera.transmittance * camera.aperture_area_m2
    return field


def simulate_frame(observation, time_index: int, draw_index: int, rng: np.random.Generator, superpixels: int = 24):
    """(raw counts (2 n, 2 n), Stokes maps) of one exposure at ``time_index`` with the material's draw ``draw_index``:
    the target at the stamp's centre."""
    raw = observation.camera.expose(frame_field(observation, time_index, draw_index, superpixels), rng)
    return raw, stokes_maps(raw, observation.camera.layout)


def montage_figure(observation, time_indices, rng: np.random.Generator, draw_index: int = 0, fig=None) -> Figure:
    """S0 and DoLP images of one simulated exposure at each of ``time_indices`` (the target at the centre)."""
    g = observation.geometry
    fig = fig or Figure(figsize=(2.6 * len(time_indices) + 0.6, 5.4), layout="constrained")
    axes = np.atleast_2d(fig.subplots(2, len(time_indices), squeeze=False))
    for col, j in enumerate(time_indices):
        _, maps = simulate_frame(observation, j, draw_index, rng)
        im0 = axes[0, col].imshow(maps.stokes[0], cmap="gray")
        im1 = axes[1, col].imshow(maps.dolp, cmap="viridis", vmin=0, vmax=1)
        axes[0, col].set_title(f"{g.times_utc[j].strftime('%H:%M:%S')} UTC\nel {g.elevation_deg[j]:.0f} deg", fontsize=8)
        for ax in axes[:, col]:
            ax.set_xticks([])
            ax.set_yticks([])
    axes[0, 0].set_ylabel("S0 (counts)")
    axes[1, 0].set_ylabel("DoLP")
    fig.colorbar(im0, ax=axes[0, :], shrink=0.8)
    fig.colorbar(im1, ax=axes[1, :], shrink=0.8)
    fig.suptitle("Simulated exposures around the target (superpixel Stokes): one draw of the material", fontsize=9)
    return fig
