"""The ``phase_matrix`` effect: light scattered once inside a porous material, with a free-form Mueller phase
matrix that is physically realizable over its whole prior (``constrained_phase``), under an interface of its own
index, with linear and circular depolarization along the paths; after NIST SCATMECH's ``First_Diffuse_BRDF_Model``
with ``Constrained_Phase_Function`` (Germer, Proc. SPIE 10655, 1065504 (2018)).

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from ...priors import Uniform
from .. import constrained_phase
from ..effect import Context
from ..parameter import Parameter
from ..single_scattering import SingleScattering, henyey_greenstein

PREFIX = "pm_"
SHAPE_NAMES = tuple(PREFIX + name for name, _ in constrained_phase.COORDINATES)


def circular_depolarization(linear, share):
    """SCATMECH's depolc from the linear one and a share in [0, 1] of its realizable bound: a leg's
    diag(1, 1 - l, 1 - l, 1 - c) is a physical depolarizer only when c <= 2 l (its coherency eigenvalue
    (2 l - c) / 4 >= 0), and c <= 1."""
    return share * jnp.minimum(1.0, 2.0 * linear)


class PhaseMatrix(SingleScattering):
    """The ``phase_matrix`` effect: first-order volume scattering with a free-form, realizable phase matrix under
    an interface of its own index."""
    name = "phase_matrix"
    mirror_symmetric = True  # isotropic: M(-dphi) = D M(dphi) D
    hidden_values = (  # a small and a large value, for the hidden-effect suite
        {"w_pm": 0.5, "g_pm": 0.3, "n_pm": 1.3, "pm_m22_0": 0.9, "pm_m22_60": 0.6, "pm_m12_60": -0.5, "pm_m22_120": 0.5,
         "pm_m12_120": -0.4},
        {"w_pm": 0.95, "g_pm": -0.2, "n_pm": 1.25, "pm_m22_0": 0.8, "pm_m22_60": 0.4, "pm_m12_60": -0.8, "pm_m34_60": 0.3,
         "pm_m22_120": 0.3, "pm_m12_120": -0.7, "pm_m22_180": 0.5},
    )
    requires = ()
    substitutes = ("subsurface",)  # a volume lobe may carry what a multiple-scattering body term fitted
    parameters = (
        Parameter("w_pm", "", Uniform(0.0, 1.0), 0.5, "single-scattering albedo of the volume scatterers",
                  physical=(0.0, 1.0)),
        Parameter("g_pm", "", Uniform(-0.9, 0.9), 0.0, "Henyey-Greenstein asymmetry of the phase function (> 0 forward)",
                  physical=(-0.999, 0.999)),
        Parameter("n_pm", "", Uniform(1.0, 2.0), 1.3, "real index of the interface the light crosses in and out "
                  "(a porous material's effective surface index)", physical=(1.0, np.inf)),
        Parameter("dl_pm", "", Uniform(0.0, 1.0), 0.0, "share of the linear polarization lost on the paths in and "
                  "out (SCATMECH's depoll)", physical=(0.0, 1.0)),
        Parameter("fc_pm", "", Uniform(0.0, 1.0), 0.0, "circular polarization lost on the paths in and out "
                  "(SCATMECH's depolc) as a share of its realizable bound min(1, 2 dl_pm)", physical=(0.0, 1.0)),
        *(Parameter(PREFIX + name, "", Uniform(-1.0, 1.0), 0.0, f"phase-matrix shape coordinate: {meaning} (the value "
                    "itself where the spline stays realizable, drawn towards the depolarizer where it would not)",
                    physical=(-1.0, 1.0))
          for name, meaning in constrained_phase.COORDINATES),
    )
    description = (
        "Light scattered once inside a porous material (NIST SCATMECH's First_Diffuse_BRDF_Model with the "
        "Constrained_Phase_Function; Germer, SPIE 10655, 2018): it refracts in through an interface of its own "
        "index n_pm, scatters once with a free-form reduced Mueller phase matrix (m22, m33, m44, m12, m34 splined "
        "between 0, 60, 120 and 180 deg of internal scattering angle) times a Henyey-Greenstein phase function "
        "(g_pm), and refracts out; f = w_pm D T(theta_r) P(Theta) T(theta_i) D / (n_pm^2 (mu_i' + mu_r')), D the "
        "linear (dl_pm) and circular depolarization along the paths. The 14 pm_* shape coordinates lie in [-1, 1] "
        "and every point of that box gives a phase matrix that is physically realizable (Cloude coherency "
        "eigenvalues >= 0) at every scattering angle. Reciprocal."
    )
    intensity = "w_pm"
    neutral = {"w_pm": 0.0}

    @staticmethod
    def nodes(values) -> constrained_phase.NodeValues:
        """The realizable node values of the phase matrix for parameter values (a dict or the context)."""
        return constrained_phase.realizable_nodes([values[name] for name in SHAPE_NAMES])

    def phase_matrix(self, ctx: Context, cos_theta):
        return constrained_phase.phase_matrix(self.nodes(ctx), henyey_greenstein(ctx["g_pm"], cos_theta), cos_theta)

    def depolarization(self, ctx: Context):
        return (ctx["dl_pm"], circular_depolarization(ctx["dl_pm"], ctx["fc_pm"]))

    def index(self, ctx: Context):
        """The interface's own real index: (n_pm, 0)."""
        return (ctx["n_pm"], 0.0 * ctx["n_pm"])
