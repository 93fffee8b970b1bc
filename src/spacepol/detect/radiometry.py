"""Photon budget and detection limit (paper eqs 34-39), with its units made explicit, in two readings of the
micro-polarizer (``reading``: the corrected one, and the paper's as printed).

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import quad

READINGS = ("paper", "corrected")


def transmission(p, reading: str):
    """Fraction of the light a pixel's polarizer passes (see module doc)."""
    if reading == "paper":
        return (1.0 + np.asarray(p, float)) / 2.0
    if reading == "corrected":
        return np.full(np.shape(p), 0.5)
    raise ValueError(f"unknown reading '{reading}' (choose from {READINGS})")


def target_electron_factor(inst: dict) -> float:
    """N_s / Phi_s of eq 35 (electrons per photon m^-2 s^-1 at the pupil), polarizer included as tau_p."""
    return (inst["pupil_area_m2"] * inst["system_transmittance"] * inst["atmospheric_transmittance"]
            * inst["polarizer_transmittance"] * inst["quantum_efficiency"] * inst["integration_time_s"]
            * (1 - inst["obscuration_ratio"] ** 2) * inst["target_filter_transmittance"] / inst["spot_pixels"])


def target_electrons(flux_m2_s, inst: dict):
    """Eq 35: N_s from the target's photon flux at the pupil (photons m^-2 s^-1)."""
    return target_electron_factor(inst) * np.asarray(flux_m2_s, float)


def background_photon_flux(magnitude):
    """Phi_B = 5.6e10 / 2.512^M_B (photons m^-2 s^-1 arcsec^-2, as eq 36 uses it)."""
    return 5.6e10 / 2.512 ** np.asarray(magnitude, float)


def background_electrons(inst: dict, p_sky, reading: str = "paper"):
    """Eq 36: N_B per pixel, with the sky's polarizer transmission of the chosen reading."""
    return (background_photon_flux(inst["background_magnitude"]) * inst["pupil_area_m2"] * inst["system_transmittance"]
            * inst["polarizer_transmittance"] * inst["quantum_efficiency"] * inst["background_integration_time_s"]
            * inst["background_filter_transmittance"] * inst["pixel_ifov_arcsec"] ** 2
            * (1 - inst["obscuration_ratio"] ** 2) * transmission(p_sky, reading))


def noise_electrons(n_target, n_background, inst: dict):
    """Eq 37: N = sqrt(N_s + N_B + N_D t_s k + N_R^2)."""
    return np.sqrt(n_target + n_background + inst["dark_current_e_per_s"] * inst["integration_time_s"] * inst["spot_pixels"]
                   + inst["read_noise_e"] ** 2)


def snr(flux_m2_s, inst: dict, p_sky=0.0, reading: str = "paper"):
    """Eq 38."""
    n_s = target_electrons(flux_m2_s, inst)
    return n_s / noise_electrons(n_s, background_electrons(inst, p_sky, reading), inst)


def limit_flux(inst: dict, p_sky=0.0, reading: str = "paper", snr_required: float | None = None):
    """The target flux at the pupil (photons m^-2 s^-1) giving the required SNR: eqs 35-38 inverted
    (N_s^2 = SNR^2 (N_s + c), the positive root)."""
    s = inst["snr_required"] if snr_required is None else snr_required
    c = noise_electrons(0.0, background_electrons(inst, p_sky, reading), inst) ** 2
    n_s = (s**2 + np.sqrt(s**4 + 4 * s**2 * c)) / 2
    return n_s / target_electron_factor(inst)


def _planck_integral(inst: dict) -> float:
    t0, bc = inst["star_temperature_K"], inst["bolometric_correction"]
    lo, hi = inst["band_low_um"] * 1e4, inst["band_high_um"] * 1e4  # angstrom

    def integrand(lam):
        return 8.48e34 * 10 ** (-0.4 * bc) / (t0**4 * lam**4) / np.expm1(1.44e8 / (lam * t0))

    return quad(integrand, lo, hi)[0]


def magnitude(flux_m2_s, inst: dict):
    """Eq 39: the stellar magnitude of a photon flux at the pupil (photons m^-2 s^-1; eq 39 itself
    works per cm^2, hence the 1e4)."""
    return 2.5 * np.log10(_planck_integral(inst) / (np.asarray(flux_m2_s, float) / 1e4))


def limiting_magnitude(p_target, inst: dict, reading: str = "paper", flux_limit=None):
    """Faintest target magnitude detected at the required SNR. The limit flux Phi_s is what must
    pass the pixel's polarizer (eq 34 puts the polarizer's (1 + P_s) into Phi_s); the target must
    bring Phi_s / T to the pupil, so its limiting magnitude is M(Phi_s) + 2.5 log10(T)."""
    flux = inst["limit_flux_photons_m2_s"] if flux_limit is None else flux_limit
    return magnitude(flux, inst) + 2.5 * np.log10(transmission(p_target, reading))


def intensity_contrast(limit_mag, sky_mag):
    """Target over sky brightness at the detection limit: 10^(-0.4 (M_lim - M_sky))."""
    return 10 ** (-0.4 * (np.asarray(limit_mag) - sky_mag))


def polarization_contrast(p_target, p_sky):
    """Table 3's polarization contrast: the target's DOP over the sky's."""
    return np.asarray(p_target, float) / np.asarray(p_sky, float)


def sphere_flux(radius_m, albedo, distance_m, phase_angle_deg, p_target, scale_photons_m2_s: float):
    """Eq 34: photons m^-2 s^-1 at the pupil from a diffuse sphere, with the prefactor's missing
    scale explicit: scale_photons_m2_s x R^2 rho (1 + P) [(pi - phi) cos phi + sin phi] / (pi L^2)."""
    phi = np.radians(phase_angle_deg)
    return (scale_photons_m2_s * radius_m**2 * albedo * (1 + np.asarray(p_target))
            * ((np.pi - phi) * np.cos(phi) + np.sin(phi)) / (np.pi * distance_m**2))
