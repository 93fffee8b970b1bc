"""The ``dop_bias`` effect: the Rician bias of a DOP estimated from noisy Stokes parameters."""

from __future__ import annotations

import jax.numpy as jnp

from ...priors import Uniform
from ..effect import Effect
from ..parameter import Parameter


class DopBias(Effect):
    """The ``dop_bias`` effect: the Rician bias of a DOP estimated from noisy Stokes parameters."""
    name = "dop_bias"
    mirror_symmetric = True  # isotropic: M(-dphi) = D M(dphi) D
    hidden_values = ({"bias": 0.01}, {"bias": 0.05})  # a small and a large value, for the hidden-effect suite
    parameters = (
        Parameter("bias", "", Uniform(0.0, 0.2), 0.02, "noise floor of the DOP estimator", physical=(0.0, 1.0)),
    )
    description = (
        "Noise bias of a measured DOP: with noisy Stokes parameters the DOP estimate is Rician, "
        "sqrt(DOP^2 + bias^2) on average, so low DOP reads high and DOP never reaches 0. Applied to the "
        "measured DOP only (the Stokes vector is the physical one); the estimate may exceed 1 by at most "
        "sqrt(1 + bias^2) - 1."
    )
    neutral = {"bias": 0.0}

    def modify_dop(self, ctx, dop):
        return jnp.sqrt(dop**2 + ctx["bias"] ** 2)
