"""The ``angle_offset`` effect: a goniometer zero error added to both polar angles."""

from __future__ import annotations

from ...priors import Uniform
from ..effect import Effect
from ..parameter import Parameter


class AngleOffset(Effect):
    """The ``angle_offset`` effect: a goniometer zero error added to both polar angles."""
    name = "angle_offset"
    mirror_symmetric = True  # isotropic: M(-dphi) = D M(dphi) D
    hidden_values = ({"delta_deg": 1.0}, {"delta_deg": 2.5})  # a small and a large value, for the hidden-effect suite
    parameters = (
        Parameter("delta_deg", "deg", Uniform(-3.0, 3.0), 0.0, "goniometer zero error added to theta_i and theta_r", physical=(-89.0, 89.0)),
    )
    description = (
        "A goniometer zero error: the true angles are theta_i + delta and theta_r + delta. Shifts the "
        "whole DOP curve along the angle axis (the geometry is then recomputed for each parameter set)."
    )
    neutral = {"delta_deg": 0.0}

    def transform_geometry(self, params, geometry):
        return geometry.with_offset(params["delta_deg"])
