"""The ``polarized_diffuse`` effect: refracted in, depolarized, refracted out (Fresnel transmission twice)."""

from __future__ import annotations

import numpy as np

from ...priors import Uniform
from ..effect import Effect
from ..interface import through_interface
from ..parameter import Parameter


class PolarizedDiffuse(Effect):
    """The ``polarized_diffuse`` effect: refracted in, depolarized, refracted out (Fresnel transmission twice)."""
    name = "polarized_diffuse"
    mirror_symmetric = True  # isotropic: M(-dphi) = D M(dphi) D
    hidden_values = ({"rho_pd": 0.05}, {"rho_pd": 0.3})  # a small and a large value, for the hidden-effect suite
    parameters = (
        Parameter("rho_pd", "", Uniform(0.0, 1.0), 0.1, "albedo of the subsurface Lambertian light", physical=(0.0, 1.0)),
    )
    requires = ("specular",)
    description = (
        "Light refracted into the material, scattered until depolarized, and refracted out again "
        "(Atkinson & Hancock 2006; the diffuse part of Baek et al. 2018): f = (rho_pd/pi) T(theta_r) D T(theta_i) "
        "with Fresnel power transmittances T = 1 - R of the macroscopic surface. Exit transmission "
        "favours p, so this light is partly polarized parallel to the exit plane (S1 < 0), most at "
        "grazing exit: it raises |DOP| at large theta_r and can flip the sign of S1 far from the specular lobe."
    )
    slot = "body"
    removable = True
    intensity = "rho_pd"
    neutral = {"rho_pd": 0.0}
    twins = {"subsurface": "no measurement on a transparent surface (the same shape T(theta_r) D T(theta_i)); "
                           "on an absorbing one the Fresnel transmission differs slightly"}

    def lobe(self, ctx):
        return through_interface(ctx, ctx["rho_pd"] / np.pi, ctx["n"], ctx["k"])
