"""The ``oxide_layer`` effect: a thin transparent film on the facets (Airy reflection coefficients)."""

from __future__ import annotations

import numpy as np

from ...priors import Uniform
from .. import fresnel
from ..effect import Effect
from ..parameter import Parameter


class OxideLayer(Effect):
    """The ``oxide_layer`` effect: a thin transparent film on the facets (Airy reflection coefficients)."""
    name = "oxide_layer"
    mirror_symmetric = True  # isotropic: M(-dphi) = D M(dphi) D
    hidden_values = ({"thickness_um": 0.05, "n_film": 1.46}, {"thickness_um": 0.25, "n_film": 1.7})  # a small and a large value, for the hidden-effect suite
    parameters = (
        Parameter("thickness_um", "um", Uniform(0.0, 1.0), 0.05, "film thickness", physical=(0.0, np.inf)),
        Parameter("n_film", "", Uniform(1.0, 2.5), 1.65, "film refractive index (transparent)", physical=(1e-6, np.inf)),
    )
    requires = ("specular",)
    description = (
        "A thin transparent film (native oxide, coating) on the facets: reflection is the coherent sum "
        "of the film's two interfaces (Airy formula), so r_s and r_p, and hence DOP, oscillate with "
        "thickness/wavelength and angle. Needs the wavelength (metadata `wavelength_um` or a column)."
    )
    neutral = {"thickness_um": 0.0}

    def applicable(self, data):
        wavelength = data.wavelength_um
        if wavelength is None or np.any(~np.isfinite(wavelength)):
            return "needs the wavelength (a '# wavelength_um: ...' line or a wavelength_um column)"
        return None

    def configure(self, ctx):
        wavelength = ctx.geometry.wavelength_um
        if wavelength is None:  # (a NaN wavelength is caught by ``applicable`` before any fit)
            from ...errors import ParameterError

            raise ParameterError("oxide_layer needs the wavelength: add '# wavelength_um: ...' to the data file")
        substrate = ctx["n"] + 1j * ctx["k"]
        d, n_f = ctx["thickness_um"], ctx["n_film"]
        ctx.fresnel_amplitudes = lambda cos, sin2: fresnel.film_amplitudes(substrate, n_f, d, wavelength, cos, sin2)
