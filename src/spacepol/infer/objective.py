"""Objectives the optimizers minimise over the prior cube.

``PaperObjective`` is eq 25, the GA's fitness: sum (P' - P)^2 / sum P^2 over the measured DOP
(a relative squared error, to be minimised; ERRATA.md).  ``NegativeLogPosterior`` is what
the sampler's initial optimisation and `emcee`'s MAP use.  Both take parameter vectors
theta (W, D) in prior order and return (W,).
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from .posterior import Posterior
from .prior_set import PriorSet


class PaperObjective:
    """The paper's objective (eq 25): the squared DOP error relative to the measured DOP's sum of squares, for the
    GA and nlopt baselines."""

    name = "eq25_relative_squared_error"

    def __init__(self, data, model, priors: PriorSet):
        if data.dop is None:
            raise ParameterError(f"{data.source}: the paper's objective (eq 25) needs measured DOP")
        self.data, self.model, self.priors = data, model, priors
        self.names = priors.names
        self._norm = float(np.sum(data.dop**2))
        if self._norm == 0:
            raise ParameterError(f"{data.source}: every DOP is 0, eq 25 is undefined")

    def __call__(self, theta):
        theta = np.atleast_2d(theta)
        dop = self.model.dop(self.priors.to_params(theta), self.data.geometry, check=False)
        return np.sum((dop - self.data.dop) ** 2, axis=-1) / self._norm


class NegativeLogPosterior:
    """-log posterior as an objective to minimise (a large finite number where the posterior is zero)."""

    name = "negative_log_posterior"

    def __init__(self, posterior: Posterior):
        self.posterior, self.priors, self.names = posterior, posterior.priors, posterior.names

    def __call__(self, theta):
        value = -self.posterior.log_prob(theta)
        return np.where(np.isfinite(value), value, 1e300)
