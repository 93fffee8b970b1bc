"""The ``depolarization`` effect: a fraction of the specular lobe depolarized, its intensity kept."""

from __future__ import annotations

from ...priors import Uniform
from ..effect import Effect
from ..parameter import Parameter


class Depolarization(Effect):
    """The ``depolarization`` effect: a fraction of the specular lobe depolarized, its intensity kept."""
    name = "depolarization"
    mirror_symmetric = True  # isotropic: M(-dphi) = D M(dphi) D
    hidden_values = ({"d_spec": 0.2}, {"d_spec": 0.6})  # a small and a large value, for the hidden-effect suite
    parameters = (
        Parameter("d_spec", "", Uniform(0.0, 1.0), 0.1, "fraction of the specular lobe depolarized", physical=(0.0, 1.0)),
    )
    requires = ("specular",)
    description = (
        "A fraction d_spec of the specularly reflected light is depolarized by multiple scattering "
        "between facets: the lobe's S1, S2, S3 are scaled by 1 - d_spec, its intensity kept. Lowers the "
        "DOP of the specular lobe at every angle by the same factor."
    )
    twins = {"extinction": "the full Mueller matrix (an analyser acts on the detector side only, depolarization on the light itself: M12 and M21 differ)"}
    separated_by = {"extinction": ("mueller",)}
    neutral = {"d_spec": 0.0}

    def modify_specular(self, ctx, lobe):
        d = ctx["d_spec"]
        if ctx.mueller:
            # (1 - d) M + d M00 diag(1,0,0,0): the depolarized share keeps its intensity for any input.
            return (lobe * (1.0 - d)).at[0, 0].add(d * lobe[0, 0])
        return lobe.at[1:].multiply(1.0 - d)
