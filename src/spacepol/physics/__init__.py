"""The forward pBRDF model: geometry, Fresnel, facet statistics, effects, and their composition."""

from .geometry import Geometry
from .model import Model, Prediction, build_model
from .effect import Effect
from .registry import registry

__all__ = ["Geometry", "Model", "Prediction", "build_model", "Effect", "registry"]
