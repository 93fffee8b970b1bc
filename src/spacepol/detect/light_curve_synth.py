"""A measured light curve as a micro-polarizer camera would give it: the target's Stokes flux over a pass
(``target.target_light``: its faces and their fixed materials) through aperture photometry on the four analyser
channels, with the noise of the target's and the sky's photons, dark current and read noise, each time step the mean
of the frames that fill it; the atmosphere's scintillation of the flux (``skylight.scintillation``) and the
polarimeter's calibration accuracy in q and u (``Camera.polarimetric_accuracy``), the floors a bright target meets;
DoLP and AoP with delta-method errors.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..io.light_curve import LightCurve
from ..skylight.scintillation import scintillation_relative
from .observation import sky_photons_at
from .target import target_light

ANALYSER_DEG = np.array([0.0, 45.0, 90.0, 135.0])
ENCLOSED = 1.0 - 2.0**-4  # a Gaussian PSF within one FWHM of its centre


def synthesized_light_curve(geometry, camera, rng: np.random.Generator, band_um=(1.5, 1.8),
                            sky_magnitude_zenith: float = 5.40, exposures: int = 1) -> LightCurve:
    """The light curve of ``geometry``'s faces (each with a fixed material) seen by ``camera`` at the times the
    satellite is above the horizon, sunlit and some face sends light to the site, each time the mean of
    ``exposures`` frames; one line where it never is."""
    light = target_light(geometry, None, {}, band_um)
    stokes = light.stokes_w_m2[:3, 0, :] * light.photons_per_joule  # (3, T) photons m^-2 s^-1
    keep = (geometry.elevation_deg > 0) & geometry.sunlit & (stokes[0] > 0)
    if not keep.any():
        raise ParameterError(f"{geometry.satellite}: below the horizon, in Earth's shadow or turning no lit face to the "
                             "site at every time of the window: no light curve to measure")
    pixels = np.pi * camera.psf_fwhm_pixels**2
    per_electron = camera.aperture_area_m2 * camera.transmittance * camera.quantum_efficiency * camera.exposure_s
    k = per_electron * ENCLOSED / 8.0
    sky_rate = sky_photons_at(geometry, sky_magnitude_zenith) * camera.pixel_scale_arcsec**2  # photons m^-2 s^-1 px^-1
    sky_c = 0.5 * sky_rate * per_electron * pixels / 4  # electrons per channel (an unpolarized share)
    floor = pixels / 4 * (camera.read_noise_e**2 + camera.dark_current_e_per_s * camera.exposure_s)
    angles = np.radians(2 * ANALYSER_DEG)[:, None]
    mean = k * (stokes[0] + stokes[1] * np.cos(angles) + stokes[2] * np.sin(angles))  # (4, T) electrons
    variance = (np.maximum(mean, 0.0) + sky_c + floor) / exposures  # of the frames' mean
    # scintillation scales the target's light in all four channels alike (the sky, extended, does not twinkle)
    twinkle = scintillation_relative(2.0 * np.sqrt(camera.aperture_area_m2 / np.pi), geometry.elevation_deg,
                                     geometry.site[2], exposures * camera.exposure_s, camera.scintillation_correction)
    counts = mean * (1.0 + twinkle * rng.standard_normal(twinkle.shape)) + np.sqrt(variance) * rng.standard_normal(mean.shape)
    s0, s1, s2 = counts.sum(axis=0) / (4 * k), (counts[0] - counts[2]) / (2 * k), (counts[1] - counts[3]) / (2 * k)
    var0 = variance.sum(axis=0) / (16 * k * k)
    var1, var2 = (variance[0] + variance[2]) / (4 * k * k), (variance[1] + variance[3]) / (4 * k * k)
    # the polarimeter's calibration error, in normalized q and u alike
    accuracy = camera.polarimetric_accuracy
    q, u = np.stack([s1, s2]) / s0 + accuracy * rng.standard_normal((2, s0.size))
    s1, s2 = q * s0, u * s0
    linear = np.hypot(s1, s2)
    safe_linear = np.maximum(linear, 1e-300)
    dolp = linear / s0
    var_linear = (s1**2 * var1 + s2**2 * var2) / safe_linear**2
    dolp_err = np.sqrt(var_linear / s0**2 + linear**2 * var0 / s0**4 + accuracy**2)
    aop_err = np.degrees(0.5 * np.sqrt((s2**2 * var1 + s1**2 * var2) / safe_linear**4 + accuracy**2 / np.maximum(dolp**2, 1e-300)))
    flux_err = np.sqrt(var0 + (twinkle * stokes[0]) ** 2)  # scintillation of the true flux, as photon noise is
    times = [t for t, on in zip(geometry.times_utc, keep) if on]
    return LightCurve(times, flux=s0[keep], flux_err=flux_err[keep], dolp=dolp[keep], dolp_err=dolp_err[keep],
                      aop_deg=0.5 * np.degrees(np.arctan2(s2, s1))[keep], aop_err_deg=aop_err[keep],
                      source=f"synthetic pass of {geometry.satellite}")
