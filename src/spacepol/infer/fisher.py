"""Fisher information of measurements at a parameter point, from JAX derivatives of the model.

For measured numbers y_i with Gaussian noise s_i (in the space where the likelihood takes it: DOP and
Mueller elements as they are, BRDF as log BRDF when its noise is relative), I = J^T diag(1 / s^2) J with
J_ij = d mu_i / d theta_j, the exact derivatives of the compiled model (``jax.jacfwd``). Its inverse,
with the priors' own precision added, is the Laplace approximation of the posterior covariance: what
``criticism.design`` uses to say which measurement would break a degeneracy, before anyone measures it.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from ..physics.compiled import Program
from ..physics.geometry import Geometry
from ..physics.model import Prediction


def jacobian(model, geometry: Geometry, observables, point: dict, names: list[str], inferred=lambda channel: True):
    """(channels, J): the predicted numbers' derivatives (n_numbers, len(names)) at ``point`` (every model
    parameter's value), one block of geometry rows per channel in the order of ``channels``, each in the space where
    its noise is Gaussian (``Observable.noise_space``; ``inferred(channel)``: whether that noise is inferred, which
    makes BRDF's relative)."""
    mueller = any(o.needs_mueller for o in observables)
    program = Program(model, geometry, mueller)
    fixed = {k: float(v) for k, v in point.items() if k not in names}
    channels = [ch for o in observables for ch in o.channels]

    def predict(theta):
        values = {**fixed, **{n: theta[j] for j, n in enumerate(names)}}
        total, dop = program(values, program.inputs)
        prediction = Prediction.from_total(total, dop, mueller)
        blocks = []
        for o in observables:
            predicted = o.predict(prediction)
            for ch in o.channels:
                blocks.append(o.noise_space(ch, predicted[ch], inferred(ch)))
        return jnp.concatenate(blocks)

    theta0 = jnp.asarray([float(point[n]) for n in names])
    return channels, np.asarray(jax.jacfwd(predict)(theta0))


def information(jac: np.ndarray, noise: np.ndarray) -> np.ndarray:
    """J^T diag(1 / noise^2) J."""
    weighted = jac / np.asarray(noise, float)[:, None]
    return weighted.T @ weighted


def prior_precision(priors, names: list[str]) -> np.ndarray:
    """Diagonal precision of each prior's Gaussian equivalent (its 90 % range / 3.29 as sd): keeps the
    information invertible where the data measure nothing (a ridge is then as wide as the prior)."""
    sd = np.array([float(np.diff(priors.priors[n].rescale(np.array([0.05, 0.95])))[0]) / 3.29 for n in names])
    return np.diag(1.0 / sd**2)
