"""The ``ggx`` effect: Trowbridge-Reitz facet slopes in place of Gaussian ones."""

from __future__ import annotations

from ..effect import Effect


class GGX(Effect):
    """The ``ggx`` effect: Trowbridge-Reitz facet slopes in place of Gaussian ones."""
    name = "ggx"
    mirror_symmetric = True  # isotropic: M(-dphi) = D M(dphi) D
    hidden_values = ({}, {})  # a small and a large value, for the hidden-effect suite
    requires = ("specular",)
    description = (
        "Trowbridge-Reitz (GGX) facet slopes instead of Gaussian ones, width a = sqrt(2) sigma: same "
        "peak curvature, much longer tails, so more light far from the specular direction (and a "
        "smoother fall of DOP away from it)."
    )
    slot = "facets"

    def configure(self, ctx):
        ctx.facet_shape = "ggx"
