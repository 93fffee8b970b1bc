"""The paper's Table 3 limit through the pass chain's detector: its Table 2 instrument as a camera, its spot, its
sky; the target flux at which the intensity detector (a matched filter on superpixel sums) reaches the paper's
required SNR, beside the paper's printed limit flux.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import numpy as np

from ..camera.sensor import Camera
from . import radiometry as R
from .point_source import point_source_stamp

STAMP_PIXELS = 8


def instrument_camera(inst: dict) -> Camera:
    """Table 2's instrument as a ``Camera`` of the chain (ideal analysers, no full well)."""
    return Camera(extinction_ratio=1e12, quantum_efficiency=inst["quantum_efficiency"], read_noise_e=inst["read_noise_e"],
                  dark_current_e_per_s=inst["dark_current_e_per_s"], full_well_e=1e30, adc_bits=32,
                  exposure_s=inst["integration_time_s"], pixel_scale_arcsec=inst["pixel_ifov_arcsec"],
                  aperture_area_m2=inst["pupil_area_m2"] * (1 - inst["obscuration_ratio"] ** 2),
                  transmittance=inst["system_transmittance"] * inst["atmospheric_transmittance"]
                  * inst["polarizer_transmittance"] * inst["target_filter_transmittance"])


def sky_stokes_per_pixel(inst: dict, p_sky: float, aop_deg: float = 0.0) -> np.ndarray:
    """(3,) the sky's Stokes photon rate per pixel before the analysers (photons s^-1), scaled so that the camera's
    exposure t_s gives eq 36's electrons (its own filter f_B and time t_B, no atmospheric transmittance)."""
    rate = (R.background_photon_flux(inst["background_magnitude"]) * inst["pixel_ifov_arcsec"] ** 2
            * inst["pupil_area_m2"] * (1 - inst["obscuration_ratio"] ** 2) * inst["system_transmittance"]
            * inst["polarizer_transmittance"] * inst["background_filter_transmittance"]
            * inst["background_integration_time_s"] / inst["integration_time_s"])
    psi = np.radians(aop_deg)
    return rate * np.array([1.0, p_sky * np.cos(2 * psi), p_sky * np.sin(2 * psi)])


def paper_spot(spot_pixels: float, size: int = STAMP_PIXELS) -> np.ndarray:
    """(size, size) the target's light on the round(k) pixels nearest the centre of the central superpixel, evenly."""
    k = int(round(spot_pixels))
    y, x = np.mgrid[0:size, 0:size]
    centre = 2 * (size // 4) + 0.5  # a superpixel's centre (superpixels start at even pixels)
    order = np.lexsort((x.ravel(), y.ravel(), np.hypot(y - centre, x - centre).ravel()))[:k]
    spot = np.zeros(size * size)
    spot[order] = 1.0 / k
    return spot.reshape(size, size)


def chain_limit(inst: dict, p_sky: float = 0.0, p_target: float = 0.0) -> dict:
    """The target flux at the aperture (S0, photons m^-2 s^-1) at which the chain's intensity detector reaches
    ``snr_required`` for Table 2's instrument, and the limits of eq 38 and of the printed Phi_s, each with its
    magnitude (eq 39; Phi_s and eq 38's flux are what passes the polarizer, the corrected reading's 1/2)."""
    camera = instrument_camera(inst)
    spot = paper_spot(inst["spot_pixels"])
    stamp = point_source_stamp(camera, sky_stokes_per_pixel(inst, p_sky), (0.0, 0.0), STAMP_PIXELS, psf=spot)
    unit = np.array([[1.0, p_target, 0.0]])
    chain_flux = inst["snr_required"] / float(stamp.deflections(unit)["intensity"][0])
    half = float(R.transmission(0.0, "corrected"))
    eq38 = float(R.limit_flux(inst, p_sky, "corrected")) / half
    printed = inst["limit_flux_photons_m2_s"] / half
    return {"chain": {"limit_flux_photons_m2_s": chain_flux, "limiting_magnitude": float(R.magnitude(chain_flux, inst))},
            "eq38": {"limit_flux_photons_m2_s": eq38, "limiting_magnitude": float(R.magnitude(eq38, inst))},
            "printed": {"limit_flux_photons_m2_s": printed, "limiting_magnitude": float(R.magnitude(printed, inst))},
            "sky_electrons_per_pixel": float(np.mean(stamp.sky_e)),
            "why": "the chain sums the signal of the k spot pixels against their noise (sqrt(k) more SNR than eq 38's "
                   "per-pixel SNR for the same light) and leaves out the target's own shot noise and eq 37's k-fold dark "
                   "current; the printed Phi_s follows from neither (paper_table3)."}
