"""Posteriors on curved bands, for the checks of the Laplace-IS gate: the paper's model on the 84 in-plane geometries
of ``default_grid`` with a known truth, DOP (absolute noise 0.005) and, optionally, a BRDF so noisy that the band the
DOP leaves stays curved."""

import numpy as np

from spacepol.infer.posterior import Posterior
from spacepol.io.measurements import Dataset
from spacepol.physics import Model
from spacepol.physics.geometry import default_grid

METAL = {"n": 1.24, "k": 6.6, "sigma": 0.2, "ks": 0.5, "rho_d": 0.1}  # the paper's aluminium
DIELECTRIC = {"n": 1.5, "k": 0.0, "sigma": 0.25, "ks": 0.5, "rho_d": 0.2}


def band_data(truth: dict, brdf_noise: float | None = None, seed: int = 0) -> Dataset:
    """DOP of ``paper`` at ``truth`` (noise 0.005, clipped to [0, 1]) and, with ``brdf_noise``, the BRDF with that
    relative noise."""
    model = Model.from_string("paper")
    grid = default_grid()
    data = Dataset(grid.theta_i, grid.theta_r, grid.dphi)
    prediction = model.evaluate(truth, data.geometry)
    rng = np.random.default_rng(seed)
    data.dop = np.clip(prediction.dop + 0.005 * rng.standard_normal(grid.size), 0, 1)
    data.dop_err = np.full(grid.size, 0.005)
    if brdf_noise is not None:
        data.brdf = prediction.brdf * (1 + brdf_noise * rng.standard_normal(grid.size))
        data.brdf_err = brdf_noise * prediction.brdf
    return data


def band_posterior(truth: dict, brdf_noise: float | None = None) -> Posterior:
    """``paper``'s posterior on ``band_data``."""
    return Posterior.build(band_data(truth, brdf_noise), Model.from_string("paper"))
