"""The ``volume_rayleigh`` effect: first-order volume scattering with the Rayleigh phase matrix."""

from __future__ import annotations

from ...priors import Uniform
from ..parameter import Parameter
from ..single_scattering import SingleScattering, code_whitney, rayleigh_phase


class VolumeRayleigh(SingleScattering):
    """The ``volume_rayleigh`` effect: first-order volume scattering with the Rayleigh phase matrix."""
    name = "volume_rayleigh"
    mirror_symmetric = True  # isotropic: M(-dphi) = D M(dphi) D
    hidden_values = ({"w_ray": 0.5}, {"w_ray": 0.95})  # a small and a large value, for the hidden-effect suite
    parameters = (
        Parameter("w_ray", "", Uniform(0.0, 1.0), 0.5, "single-scattering albedo of the small (Rayleigh) scatterers",
                  physical=(0.0, 1.0)),
    )
    description = (
        "Light scattered once inside the material by scatterers much smaller than the wavelength: `volume` with "
        "the Rayleigh phase matrix (phase function 3 (1 + cos^2 Theta) / (16 pi), fully polarized at 90 deg, no "
        "retardance); f = w_ray T(theta_r) P(Theta) T(theta_i) / (n^2 (mu_i' + mu_r')). Reciprocal."
    )
    intensity = "w_ray"
    neutral = {"w_ray": 0.0}

    def phase_matrix(self, ctx, cos_theta):
        return code_whitney(rayleigh_phase(cos_theta), cos_theta, 1.0, 0.0)
