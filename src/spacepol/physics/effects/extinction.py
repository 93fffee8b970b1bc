"""The ``extinction`` effect: an analyser with a finite extinction ratio (S1, S2, S3 scaled)."""

from __future__ import annotations

from ...priors import Uniform
from ..effect import Effect
from ..parameter import Parameter


class Extinction(Effect):
    """The ``extinction`` effect: an analyser with a finite extinction ratio (S1, S2, S3 scaled)."""
    name = "extinction"
    mirror_symmetric = True  # isotropic: M(-dphi) = D M(dphi) D
    hidden_values = ({"e": 0.9}, {"e": 0.7})  # a small and a large value, for the hidden-effect suite
    parameters = (
        Parameter("e", "", Uniform(0.5, 1.0), 0.95, "analyser efficiency: measured DOP = e x true DOP", physical=(0.0, 1.0)),
    )
    description = (
        "An imperfect analyser (finite extinction ratio) sees S1, S2, S3 scaled by e, so the measured "
        "DOP is e times the true one at every angle; intensity unchanged. On DOP and BRDF data it is a "
        "twin of `depolarization` wherever the diffuse light is unpolarized. An instrument effect on the "
        "detector side, so the measured Mueller matrix is not reciprocal."
    )
    reciprocal = False
    twins = {"depolarization": "the full Mueller matrix (an analyser acts on the detector side only, depolarization on the light itself: M12 and M21 differ)"}
    separated_by = {"depolarization": ("mueller",)}
    neutral = {"e": 1.0}

    def modify_stokes(self, ctx, total):
        return total.at[1:].multiply(ctx["e"])
