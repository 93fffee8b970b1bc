"""The posterior as pure JAX functions of one parameter vector: what gradient methods differentiate.

The likelihood's compiled function (``Likelihood.function``) takes a matrix of parameter sets; here it
is wrapped for one vector ``theta`` (the free parameters in ``priors.names`` order, fixed ones compiled
in), with the declared priors' log density in JAX (``Prior.ln_prob`` traces). NUTS composes it with
the logit space (``sampling_space``); the multistart L-BFGS (``optimum``) with the prior cube.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from .posterior import Posterior


def log_likelihood_function(posterior: Posterior):
    """theta (D,) -> the log-likelihood (a JAX scalar; 0 for a prior-only posterior)."""
    if posterior.prior_only:
        return lambda theta: jnp.zeros(())
    names = tuple(posterior.names)
    scalars = tuple(sorted((k, float(v)) for k, v in posterior.priors.fixed.items()))
    levels = getattr(posterior, "levels", ())  # a ProfiledPosterior's noise levels, at their maximum per set
    if levels:
        profiled = posterior.likelihood.function(2, names, scalars, levels)
        return lambda theta: profiled(theta[None, :])[0, 0]
    total = posterior.likelihood.function(1, names, scalars)
    return lambda theta: total(theta[None, :])[0]


def log_prior_function(posterior: Posterior):
    """theta (D,) -> the declared priors' log density (-inf outside their support)."""
    priors = [posterior.priors.priors[n] for n in posterior.names]
    return lambda theta: sum(p.ln_prob(theta[j]) for j, p in enumerate(priors))


def cube_objective(posterior: Posterior):
    """A compiled u (D,) -> (-log posterior at theta = rescale(u), its gradient in u), u in [0, 1]^D (the cube
    the optimizers search); numpy in and out, non-finite values as 1e300 with a zero gradient."""
    ll, lp = log_likelihood_function(posterior), log_prior_function(posterior)
    priors = [posterior.priors.priors[n] for n in posterior.names]

    def negative_log_posterior(u):
        theta = jnp.stack([p.rescale(u[j]) for j, p in enumerate(priors)])
        return -(ll(theta) + lp(theta))

    compiled = jax.jit(jax.value_and_grad(negative_log_posterior))

    def value_and_gradient(u):
        value, grad = compiled(jnp.asarray(u, float))
        value, grad = float(value), np.asarray(grad, float)
        if not np.isfinite(value):
            return 1e300, np.zeros_like(grad)
        return value, np.where(np.isfinite(grad), grad, 0.0)  # e.g. sqrt(k) at k = 0: that direction held

    return value_and_gradient
