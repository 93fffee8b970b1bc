"""A model written down completely, so that a run's model can be rebuilt from its folder: its effects in order,
where each plug-in effect came from, the wavelengths of a model over several of them and their dispersion laws.

``spec_of(model)`` -> a JSON-able dict; ``model_from_spec(spec)`` -> the same Model or SpectralModel (plug-ins
loaded again from their files). A bare model name (folders written before specs were stored) still works, for
one-wavelength models only: a name cannot say which wavelengths a spectral model had, so it is refused where
the summary shows per-wavelength parameters.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import SpacepolError
from .model import Model
from .registry import registry
from .spectral import SpectralModel


def spec_of(model, data_wavelengths_um=None) -> dict:
    """{"effects", "plugins", "wavelengths_um", "dispersion"} of a Model or SpectralModel; a one-wavelength Model
    records the wavelengths of the data it was fitted to (``data_wavelengths_um``, None when the data have none)."""
    inner = model.model if isinstance(model, SpectralModel) else model
    effects = [e.name for e in inner.effects]
    spec = {"effects": effects, "plugins": {name: registry.sources[name] for name in effects if name in registry.sources},
            "wavelengths_um": None, "dispersion": {}}
    if isinstance(model, SpectralModel):
        spec["wavelengths_um"] = list(model.wavelengths)
        spec["dispersion"] = dict(model.dispersion)
    elif data_wavelengths_um is not None:
        spec["wavelengths_um"] = [float(w) for w in np.unique(data_wavelengths_um)]
    return spec


def model_from_spec(spec, where: str = "run") -> Model | SpectralModel:
    """The model ``spec_of`` wrote (or a model name, for one wavelength)."""
    if isinstance(spec, str):
        return Model.from_string(spec)
    try:
        effects, plugins = list(spec["effects"]), dict(spec.get("plugins", {}))
        wavelengths, dispersion = spec.get("wavelengths_um"), dict(spec.get("dispersion") or {})
    except (KeyError, TypeError, AttributeError):
        raise SpacepolError(f"{where}: the stored model spec is damaged (need effects, plugins, wavelengths_um)") from None
    for name, source in plugins.items():
        if name in registry.names():
            continue
        path, sep, _ = source.rpartition(":")
        if not sep or not Path(path).is_file():
            raise SpacepolError(f"{where}: the model uses plug-in effect '{name}' from {source}, which is not at hand "
                                f"(load it with --effect FILE.py:Name)")
        registry.load_file(source)
    model = Model.from_string("+".join(effects))
    if wavelengths and len(wavelengths) > 1:
        return SpectralModel(model, wavelengths, dispersion)
    return model
