"""The forward pBRDF model: geometry, Fresnel, facet statistics, effects, and their composition."""

from .geometry import Geometry
from .model import Model, Prediction
from .effect import Effect
from .registry import registry

__all__ = ["Geometry", "Model", "Prediction", "Effect", "registry"]
