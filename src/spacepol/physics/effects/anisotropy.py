"""The ``anisotropy`` effect: slope widths along two turned axes in place of sigma."""

from __future__ import annotations

import numpy as np

from ...priors import Uniform
from ..effect import Effect
from ..parameter import Parameter


class Anisotropy(Effect):
    """The ``anisotropy`` effect: slope widths along two turned axes in place of sigma."""
    name = "anisotropy"
    hidden_values = ({"sigma_x": 0.12, "sigma_y": 0.3, "psi": 30.0}, {"sigma_x": 0.08, "sigma_y": 0.4, "psi": 60.0})  # a small and a large value, for the hidden-effect suite
    parameters = (
        Parameter("sigma_x", "", Uniform(0.02, 0.8), 0.2, "slope standard deviation along the surface x' axis", physical=(1e-6, np.inf)),
        Parameter("sigma_y", "", Uniform(0.02, 0.8), 0.2, "slope standard deviation along the surface y' axis", physical=(1e-6, np.inf)),
        Parameter("psi", "deg", Uniform(0.0, 180.0), 0.0, "angle of x' from the source azimuth"),
    )
    requires = ("specular",)
    removes = ("sigma",)
    description = (
        "Anisotropic roughness (brushed or rolled metal): slope widths sigma_x, sigma_y along axes "
        "turned by psi from the plane of incidence replace sigma. The specular lobe stretches along "
        "the rough axis, so out-of-plane data change with the sample's rotation."
    )
    splits = {"sigma_x": "sigma", "sigma_y": "sigma"}

    def identifiable(self, values):
        """(sigma_x, sigma_y, psi) and (sigma_y, sigma_x, psi + 90), and psi and psi + 180, describe the same
        surface: order the widths (sigma_x <= sigma_y) and take psi modulo 180 after the swap."""
        sx, sy, psi = (np.asarray(values[n], float) for n in ("sigma_x", "sigma_y", "psi"))
        swap = sx > sy
        return {**values, "sigma_x": np.where(swap, sy, sx), "sigma_y": np.where(swap, sx, sy),
                "psi": np.where(swap, psi + 90.0, psi) % 180.0}

    def configure(self, ctx):
        ctx.anisotropic_slopes = (ctx["sigma_x"], ctx["sigma_y"], ctx["psi"])
