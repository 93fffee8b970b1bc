"""Posterior = likelihood x priors, vectorised over walkers (parameter sets)."""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from .likelihood import Likelihood
from .prior_set import PriorSet


class Posterior:
    def __init__(self, likelihood: Likelihood, priors: PriorSet, prior_only: bool = False):
        self.likelihood, self.priors = likelihood, priors
        self.prior_only = prior_only  # sample the prior alone (a check of the sampler and the priors)
        self.names = priors.names
        self.n_evaluations = 0
        if likelihood.n_obs < priors.ndim:
            raise ParameterError(
                f"{likelihood.data.source}: {likelihood.n_obs} observations are fewer than the "
                f"{priors.ndim} free parameters ({', '.join(priors.names)})"
            )

    @classmethod
    def build(cls, data, model, prior_overrides=None, observables=None, robust=False, where="priors"):
        likelihood = Likelihood(data, model, observables=observables, robust=robust)
        priors = PriorSet(model.parameters + likelihood.nuisance, prior_overrides, where=where)
        return cls(likelihood, priors)

    @property
    def ndim(self) -> int:
        return self.priors.ndim

    def log_prob_pointwise(self, theta) -> np.ndarray:
        theta = np.atleast_2d(theta)
        return self.likelihood.pointwise(self.priors.to_params(theta))

    def log_prob(self, theta) -> np.ndarray:
        """log posterior (up to a constant) for each row of theta (W, D); -inf outside the priors."""
        theta = np.atleast_2d(theta)
        lp = self.priors.ln_prob(theta)
        inside = np.isfinite(lp)
        if self.prior_only:
            return lp
        if np.any(inside):
            ll = self.log_prob_pointwise(theta[inside]).sum(axis=-1)
            self.n_evaluations += int(inside.sum())
            lp[inside] += np.where(np.isfinite(ll), ll, -np.inf)
        return lp

    def __call__(self, theta):
        return self.log_prob(theta)
