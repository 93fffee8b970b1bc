"""The ``shadowing`` effect: the paper's empirical shadowing/masking of the specular lobe."""

from __future__ import annotations

import numpy as np

from ...priors import Uniform
from ..effect import Effect
from ..parameter import Parameter
from ..shadowing import PAPER_CONSTANTS, paper_shadowing


class Shadowing(Effect):
    """The ``shadowing`` effect: the paper's empirical shadowing/masking of the specular lobe."""
    name = "shadowing"
    mirror_symmetric = True  # isotropic: M(-dphi) = D M(dphi) D
    parameters = tuple(
        Parameter(name, "", Uniform(lo, hi), PAPER_CONSTANTS[name], text, fixed=True, physical=(0.0, np.inf))
        for name, lo, hi, text in [
            ("sigma_p", 0.0, 0.2, "empirical shadowing strength (eq 8)"),
            ("sigma_r", 0.0, 0.2, "empirical masking relief term (eq 7)"),
            ("u_p", 0.0, 30.0, "growth of w_p with facet tilt (eq 8)"),
            ("v_p", 0.05, 10.0, "tilt scale of w_p (eq 8)"),
        ]
    )
    requires = ("specular",)
    description = (
        "The paper's empirical shadowing/masking G (eqs 7-8, corrected tan(beta_p)): facets hidden "
        "from the source or the detector do not contribute. Darkens the specular lobe at grazing "
        "incidence or exit; it multiplies S0, S1 and S2 alike, so it changes DOP only through the "
        "balance with the diffuse lobes. Its four constants are fixed at the paper's values unless freed."
    )
    slot = "shadowing"
    removable = True

    def specular_factor(self, ctx):
        return paper_shadowing(ctx.geometry, *(ctx[name] for name in PAPER_CONSTANTS))
