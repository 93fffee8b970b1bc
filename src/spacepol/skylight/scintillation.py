"""Scintillation: the atmosphere's twinkling of a point source's flux through a telescope (Young 1967), in the form
and with the median correction of Osborn et al. (2015, MNRAS 452, 1707, eq. 7).

sigma^2 = 1e-5 C_Y^2 D^(-4/3) t^(-1) X^3 exp(-2 h / H): D the aperture's diameter (m), t the exposure (s, longer than
the wind's crossing time of the aperture, a few ms), X the airmass, h the site's height (m), H = 8,000 m the
atmosphere's scale height, C_Y = 1.5 the median over sites (1 gives Young's formula). The relative error of the flux
is the same in all four analyser channels of a micro-polarizer camera, so DoLP and AoP do not see it.
"""

from __future__ import annotations

import numpy as np

SCALE_HEIGHT_M = 8000.0
MEDIAN_CORRECTION = 1.5  # Osborn et al. 2015: the median C_Y over 11 sites (Young's own coefficient is 1)


def scintillation_relative(aperture_diameter_m: float, elevation_deg, height_m: float, exposure_s: float,
                           correction: float = MEDIAN_CORRECTION) -> np.ndarray:
    """The relative standard deviation of a point source's flux from scintillation at ``elevation_deg`` (airmass
    1 / sin e: within 1 % of Kasten and Young's above 15 deg)."""
    airmass = 1.0 / np.sin(np.radians(np.clip(elevation_deg, 1e-3, 90.0)))
    variance = 1e-5 * correction**2 * aperture_diameter_m ** (-4.0 / 3.0) / exposure_s * airmass**3 \
        * np.exp(-2.0 * height_m / SCALE_HEIGHT_M)
    return np.sqrt(variance)
