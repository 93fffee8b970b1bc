"""A micro-polarizer sensor's response: from the Stokes photon rate falling on each pixel to its raw count.

Each pixel's analyser at angle theta passes t = [(T_max + T_min) S0 + (T_max - T_min)(S1 cos 2 theta +
S2 sin 2 theta)] / 2 of the light (T_max = 1, T_min = 1 / extinction ratio: a real wire grid leaks the crossed
polarization); the quantum efficiency turns photons into electrons, dark current adds its own, both Poisson; the
read noise is Gaussian; the full well clips; the ADC divides by the gain and truncates to its bits. Stokes
parameters computed as if the analysers were ideal then hold S0 (T_max + T_min) and S1, S2 (T_max - T_min): the
measured DoLP is the true one times (ER - 1) / (ER + 1), the extinction ratio's leakage.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ..errors import ParameterError
from ..skylight.scintillation import MEDIAN_CORRECTION
from .mosaic import IMX250MZR, Layout


@dataclass(frozen=True)
class Camera:
    """A micro-polarizer camera. Defaults: a Sony IMX250MZR-class sensor (extinction ratio, read noise, full well
    and ADC from its datasheet class; quantum efficiency for the near infrared), 1 s exposure, behind the paper's
    telescope (aperture, transmittance); set ``pixel_scale_arcsec`` and ``psf_fwhm_pixels`` for yours."""

    extinction_ratio: float = 300.0
    quantum_efficiency: float = 0.65
    read_noise_e: float = 2.3
    dark_current_e_per_s: float = 3.0
    full_well_e: float = 10_500.0
    adc_bits: int = 12
    exposure_s: float = 1.0
    pixel_scale_arcsec: float = 0.5
    psf_fwhm_pixels: float = 2.0
    aperture_area_m2: float = 2.544  # the telescope: the paper's A_0 (Table 2)
    transmittance: float = 0.63  # optics x atmosphere: the paper's tau_0 tau_s = 0.9 x 0.7
    # the polarimeter's calibration accuracy (1 sigma in normalized q and u each), the floor of a bright target's
    # DoLP error: "sub-percent" after a careful calibration of IMX250MZR-class sensors (Stockmans et al. 2024,
    # JATIS), more behind a telescope's own instrumental polarization; 0 an ideal polarimeter (photon noise only)
    polarimetric_accuracy: float = 0.005
    # scintillation's C_Y (skylight.scintillation): 1.5 the median over sites, 0 none
    scintillation_correction: float = MEDIAN_CORRECTION
    layout: Layout = IMX250MZR
    exposure_set: bool = True  # False: ``observe`` chooses the exposure for the pass's sky (camera files without one)

    def __post_init__(self):
        checks = {"extinction_ratio": self.extinction_ratio > 1, "quantum_efficiency": 0 < self.quantum_efficiency <= 1,
                  "read_noise_e": self.read_noise_e >= 0, "dark_current_e_per_s": self.dark_current_e_per_s >= 0,
                  "full_well_e": self.full_well_e > 0, "adc_bits": 1 <= self.adc_bits <= 32,
                  "exposure_s": self.exposure_s > 0, "pixel_scale_arcsec": self.pixel_scale_arcsec > 0,
                  "psf_fwhm_pixels": self.psf_fwhm_pixels > 0, "aperture_area_m2": self.aperture_area_m2 > 0,
                  "transmittance": 0 < self.transmittance <= 1,
                  "polarimetric_accuracy": 0 <= self.polarimetric_accuracy < 1,
                  "scintillation_correction": self.scintillation_correction >= 0}
        for name, ok in checks.items():
            value = getattr(self, name)
            if not (np.isfinite(value) and ok):
                raise ParameterError(f"camera {name} = {value!r} is impossible")

    @property
    def gain_e_per_dn(self) -> float:
        """Electrons per count: the full well spread over the ADC's range."""
        return self.full_well_e / (2**self.adc_bits - 1)

    @property
    def transmissions(self) -> tuple[float, float]:
        """(T_max + T_min, T_max - T_min) of the analysers."""
        t_min = 1.0 / self.extinction_ratio
        return 1.0 + t_min, 1.0 - t_min

    def angle_map(self, shape: tuple[int, int]) -> np.ndarray:
        """(H, W) analyser angle (deg) of every pixel."""
        tile = np.array(self.layout.angles, float)
        return np.tile(tile, (shape[0] // 2, shape[1] // 2))

    def passed(self, s0, s1, s2, theta_rad):
        """What an analyser at ``theta_rad`` passes of light with linear Stokes parameters s0, s1, s2 (broadcast)."""
        total, diff = self.transmissions
        return 0.5 * (total * s0 + diff * (s1 * np.cos(2 * theta_rad) + s2 * np.sin(2 * theta_rad)))

    def expected_electrons(self, stokes_photons_s: np.ndarray) -> np.ndarray:
        """(H, W) mean electrons per pixel in one exposure from the Stokes photon rate (3, H, W) per pixel
        (photons s^-1 on the pixel before its analyser), dark current included."""
        s0, s1, s2 = stokes_photons_s
        passed = self.passed(s0, s1, s2, np.radians(self.angle_map(s0.shape)))
        return (self.quantum_efficiency * passed + self.dark_current_e_per_s) * self.exposure_s

    def expose(self, stokes_photons_s: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """(H, W) raw counts of one exposure: Poisson electrons, Gaussian read noise, the full well, the ADC."""
        electrons = rng.poisson(self.expected_electrons(stokes_photons_s)).astype(float)
        electrons += self.read_noise_e * rng.standard_normal(electrons.shape)
        electrons = np.clip(electrons, 0.0, self.full_well_e)
        return np.floor(electrons / self.gain_e_per_dn)

    def counts_to_photons(self, counts: np.ndarray) -> np.ndarray:
        """Counts back to photons s^-1 before the analyser (dark current subtracted, the ADC's mean truncation of
        half a count added back)."""
        electrons = (counts + 0.5) * self.gain_e_per_dn - self.dark_current_e_per_s * self.exposure_s
        return electrons / (self.quantum_efficiency * self.exposure_s)


def camera_from_toml(path) -> Camera:
    """A Camera from a TOML file's ``[camera]`` table (keys as the Camera's fields, units in their names)."""
    import tomllib

    try:
        with open(path, "rb") as fh:
            table = tomllib.load(fh).get("camera", {})
    except FileNotFoundError:
        raise ParameterError(f"{path}: file not found") from None
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{path}: not valid TOML ({exc})") from None
    known = {f.name for f in fields(Camera) if f.name not in ("layout", "exposure_set")}
    unknown = sorted(set(table) - known)
    if unknown:
        raise ParameterError(f"{path}: [camera] has no key {', '.join(unknown)} (known: {', '.join(sorted(known))})")
    for key, value in table.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ParameterError(f"{path}: [camera] {key} = {value!r} must be a number in the unit its name gives")
    return Camera(**table, exposure_set="exposure_s" in table)
