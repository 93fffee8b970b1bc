"""The forward model from Python: ``forward`` (a model at given geometries) and ``synth`` (a measurement file from
any model, with noise)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..io.dataset import Dataset
from .inputs import build_model, parameter_values


def forward(model, geometry, values: dict | None = None):
    """The model's Prediction (Stokes vector, DOP, AoP, BRDF, Mueller matrix) at ``geometry`` (a Geometry, a
    Dataset or a file of geometries) for parameter ``values`` (defaults for the rest). Non-finite or overflowing
    output is an error naming the values."""
    from ..physics.geometry import Geometry

    model = build_model(model)
    if isinstance(geometry, (str, Path)):
        from ..io.measurements import read_measurements

        geometry = read_measurements(geometry, require_observable=False)
    geometry = geometry.geometry if isinstance(geometry, Dataset) else geometry
    if not isinstance(geometry, Geometry):
        raise ParameterError("forward: geometry must be a Geometry, a Dataset or a file of geometries")
    full = parameter_values(model, values)
    return model.check_plugins(full, geometry).require_finite(values or {}, model.name)


def synth(model, values: dict | None = None, geometry=None, *, noise_dop: float = 0.0, noise_brdf: float | None = None,
          wavelength_um: float | None = None, seed: int = 0, out=None) -> Dataset:
    """A synthetic data set: the model's DOP at ``geometry`` (a Geometry, a Dataset, a file, or the paper's default
    grid) with Gaussian noise ``noise_dop`` (absolute, clipped to [0, 1]) and, when ``noise_brdf`` is given, the
    BRDF with that relative noise. The truth is in ``metadata`` (``truth_NAME``); ``out`` writes it as a CSV."""
    from ..io.measurements import read_measurements, write_table
    from ..physics.geometry import Geometry, default_grid

    model = build_model(model)
    full = parameter_values(model, values)
    if noise_dop < 0 or (noise_brdf is not None and noise_brdf < 0):
        raise ParameterError("noise levels must be >= 0")
    if isinstance(geometry, (str, Path)):
        geometry = read_measurements(geometry, require_observable=False)
    geometry = default_grid() if geometry is None else geometry.geometry if isinstance(geometry, Dataset) else geometry
    wavelength = geometry.wavelength_um
    if wavelength_um is not None:
        wavelength = np.full(geometry.size, float(wavelength_um))
        geometry = Geometry(geometry.theta_i, geometry.theta_r, geometry.dphi, wavelength)
    rng = np.random.default_rng(seed)
    prediction = model.check_plugins(full, geometry).require_finite(values or {}, model.name)
    columns = {"theta_i": geometry.theta_i, "theta_r": geometry.theta_r, "dphi": geometry.dphi,
               "dop": np.clip(prediction.dop + rng.normal(0.0, noise_dop, geometry.size), 0.0, 1.0)}
    if noise_dop > 0:
        columns["dop_err"] = np.full(geometry.size, noise_dop)
    if noise_brdf is not None:
        columns["brdf"] = np.maximum(prediction.brdf * (1.0 + rng.normal(0.0, noise_brdf, geometry.size)), 0.0)
        if noise_brdf > 0:
            columns["brdf_err"] = noise_brdf * prediction.brdf
    if wavelength is not None:
        columns["wavelength_um"] = np.asarray(wavelength, float)
    meta = {"source": "spacepol synth", "model": model.name, "seed": seed, "noise_dop": noise_dop,
            **{f"truth_{k}": v for k, v in full.items()}}
    if out is not None:
        write_table(out, columns, meta)
    return Dataset(**{k: np.asarray(v, float) for k, v in columns.items()}, metadata=meta,
                   source=str(out) if out is not None else "spacepol synth")
