"""The paper's Table 3, recomputed from its own inputs: what reproduces and what does not, and why.

Inputs as printed: target DOP P_s in [0.002, 0.48] (Figure 9's range), sky DOP P_B = 0.32 and
0.89, Table 2's instrument, Phi_s = 8.472e5 photons m^-2 s^-1 at the detection limit.
"""

from __future__ import annotations

import numpy as np

from ..skylight.rayleigh import RayleighSky
from . import radiometry as R

P_TARGET_RANGE = (0.002, 0.48)
ROWS = [  # (zenith, azimuth, sky DOP, limiting magnitude, raw intensity contrast, polarization contrast) as printed
    {"case": "A = 10 deg, E = 101 deg 28'", "zenith_deg": 10.0, "azimuth_deg": 101 + 28 / 60, "sky_dop": 0.32,
     "limiting_magnitude": (8.86, 9.28), "intensity_contrast": (0.028, 0.042), "polarization_contrast": (0.006, 1.5)},
    {"case": "A = 60 deg, E = 101 deg 28'", "zenith_deg": 60.0, "azimuth_deg": 101 + 28 / 60, "sky_dop": 0.89,
     "limiting_magnitude": (8.83, 9.23), "intensity_contrast": (0.029, 0.043), "polarization_contrast": (0.002, 0.539)},
]
PAPER_SUN = (29.5, -(4 + 32 / 60))  # the paper's stated solar zenith and azimuth (ERRATA: wrong for the date)
TRUE_SUN = (66.49, 182.12)  # astropy, 43 deg 8' N 125 deg 32' E, 2020-12-16 11:42 UTC+8


def agrees(value: float, printed: float) -> bool:
    """Does ``value`` round to the printed number (to the digits it was printed with)?"""
    decimals = len(repr(float(printed)).split(".")[1])
    return abs(value - printed) <= 0.5 * 10.0**-decimals + 1e-12


def recompute(inst: dict) -> list[dict]:
    """Every Table 3 number recomputed, with a verdict and the reason."""
    out = []
    p = np.array(P_TARGET_RANGE)
    for row in ROWS:
        pol = R.polarization_contrast(p, row["sky_dop"])
        m_paper = R.limiting_magnitude(p, inst, "paper")
        m_plain = float(R.magnitude(inst["limit_flux_photons_m2_s"], inst))
        skies = {f"Rayleigh P_max=1, {label} sun": float(RayleighSky(1.0).dop(row["zenith_deg"], row["azimuth_deg"], sun))
                 for label, sun in (("paper's", PAPER_SUN), ("true", TRUE_SUN))}
        # the one sky magnitude that would give the printed raw contrasts from the printed magnitudes
        m_sky = [float(m + 2.5 * np.log10(c)) for m, c in zip(row["limiting_magnitude"], row["intensity_contrast"][::-1])]
        out.append({
            "case": row["case"],
            "polarization_contrast": {"paper": row["polarization_contrast"], "recomputed": [float(x) for x in pol],
                                      "reproduced": all(agrees(v, printed) for v, printed in zip(pol, row["polarization_contrast"])),
                                      "why": "P_s / P_B with P_s in [0.002, 0.48]: exact."},
            "sky_dop": {"paper": row["sky_dop"], "recomputed": skies, "reproduced": False,
                        "why": "eq 28 gives neither value at this direction with the paper's sun or the true one, "
                               "for any P_max <= 1 that also fits the other row."},
            "limiting_magnitude": {"paper": row["limiting_magnitude"], "recomputed_eq39": m_plain,
                                   "recomputed_with_(1+P_s)/2": [float(x) for x in m_paper], "reproduced": False,
                                   "why": "eq 39 (angstrom, per cm^2) gives 9.91 for Phi_s = 8.472e5; with the polarizer's "
                                          "(1 + P_s)/2 it gives [9.16, 9.59]; no reading found gives the printed range."},
            "intensity_contrast": {"paper": row["intensity_contrast"], "implied_sky_magnitude": m_sky, "reproduced": False,
                                   "why": "follows from the printed magnitudes only with a sky of about 5.40 mag, which the "
                                          "paper never states (its M_B = 22 is a night-sky value)."},
        })
    return out
