"""The ``volume`` effect: first-order volume scattering with the Code-Whitney phase matrix under the interface."""

from __future__ import annotations

from ...priors import Uniform
from ..parameter import Parameter
from ..single_scattering import SingleScattering, code_whitney, henyey_greenstein


class Volume(SingleScattering):
    """The ``volume`` effect: first-order volume scattering with the Code-Whitney phase matrix under the interface."""
    name = "volume"
    mirror_symmetric = True  # isotropic: M(-dphi) = D M(dphi) D
    hidden_values = ({"w_vol": 0.5, "g_vol": 0.3, "pl_vol": 0.8, "pc_vol": 0.0}, {"w_vol": 0.95, "g_vol": -0.2, "pl_vol": 0.9, "pc_vol": 0.3})  # a small and a large value, for the hidden-effect suite
    parameters = (
        Parameter("w_vol", "", Uniform(0.0, 1.0), 0.5, "single-scattering albedo of the volume scatterers (scattering over "
                  "attenuation, the host's absorption included)", physical=(0.0, 1.0)),
        Parameter("g_vol", "", Uniform(-0.9, 0.9), 0.0, "Henyey-Greenstein asymmetry of the phase function (> 0 forward)",
                  physical=(-0.999, 0.999)),
        Parameter("pl_vol", "", Uniform(-1.0, 1.0), 1.0, "largest degree of linear polarization of once-scattered light "
                  "(at 90 deg; 1 for Rayleigh scatterers, > 0 perpendicular to the scattering plane)", physical=(-1.0, 1.0)),
        Parameter("pc_vol", "", Uniform(-1.0, 1.0), 0.0, "the P34 (retardance) term's largest value: circular polarization "
                  "made from linear by one scattering", physical=(-1.0, 1.0)),
        Parameter("s_vol", "", Uniform(-1.0, 1.0), 0.0, "skew of the P34 term towards small angles (Code-Whitney s)",
                  fixed=True),
        Parameter("dl_vol", "", Uniform(0.0, 1.0), 0.0, "share of the linear polarization lost on the paths in and out "
                  "(SCATMECH's depoll)", physical=(0.0, 1.0)),
        Parameter("dc_vol", "", Uniform(0.0, 1.0), 0.0, "share of the circular polarization lost on the paths in and out "
                  "(SCATMECH's depolc)", physical=(0.0, 1.0)),
    )
    description = (
        "Light scattered once inside the material (NIST SCATMECH's First_Diffuse_BRDF_Model with the "
        "Code-Whitney phase matrix): it refracts in through the interface (Fresnel transmission of the facets' "
        "n, k), scatters once with a Henyey-Greenstein phase function (asymmetry g_vol) carrying linear "
        "polarization (P12, largest at 90 deg: pl_vol) and retardance (P34: pc_vol), and refracts out; "
        "f = w_vol T(theta_r) P(Theta) T(theta_i) / (n^2 (mu_i' + mu_r')). Unlike multiply scattered light it "
        "stays polarized out of the plane of incidence and fills the linear Mueller block with structure that "
        "follows the internal scattering angle; dl_vol and dc_vol (SCATMECH's depoll, depolc) let part of its linear "
        "and circular polarization be lost on the way in and out, in proportion to each path's length. Reciprocal. "
        "Add `subsurface` for the light scattered many times."
    )
    intensity = "w_vol"
    neutral = {"w_vol": 0.0}

    def phase_matrix(self, ctx, cos_theta):
        phase = henyey_greenstein(ctx["g_vol"], cos_theta)
        return code_whitney(phase, cos_theta, ctx["pl_vol"], ctx["pc_vol"], ctx["s_vol"])

    def depolarization(self, ctx):
        return (ctx["dl_vol"], ctx["dc_vol"])
