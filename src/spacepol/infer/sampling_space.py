"""Where the samplers move: each free parameter as the logit of its prior's CDF.

    z_j = logit(F_j(theta_j)),    theta_j = F_j^-1(sigmoid(z_j))

In z every declared prior becomes exactly the standard logistic density, so

    log p(z | data) = log L(theta(z)) + sum_j [log sigmoid(z_j) + log sigmoid(-z_j)]

(the Jacobian |d theta / d z| times the prior density is that logistic density): the priors stay as
declared, and there are no bounds to step over.

Why: the degeneracies the physics creates are multiplicative. DOP sees k_s / rho_d, not each (scaling
both leaves DOP unchanged), so with uniform priors the posterior is a wedge from the origin of the
(k_s, rho_d) plane, 100x narrower near zero than near the top, which no fixed proposal scale crosses
quickly. Near a lower bound z is log(theta - lower), so the wedge becomes a straight band of constant
width (log k_s - log rho_d = const): emcee's affine-invariant moves and NUTS's dense mass matrix both
follow a straight band, whatever its direction (``benchmarks/inversion_speed.py``: tau 50-76 -> ~30
steps on the 84-point DOP set). Any other linear ridge the Fisher analysis finds is handled the same way.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from .prior_set import PriorSet
from .priors import Uniform

_U_FLOOR = 1e-15  # a parameter exactly at a bound maps to a finite z (|z| <= 34.5)


class SamplingSpace:
    """The logit-of-CDF coordinates of a PriorSet's free parameters (numpy and JAX)."""

    name = "logit-cdf"

    def __init__(self, priors: PriorSet):
        self.priors = priors
        self.names = priors.names
        free = [priors.priors[n] for n in self.names]
        self._uniform = None
        if all(type(p) is Uniform for p in free):
            lower = np.array([p.lower for p in free])
            self._uniform = (lower, np.array([p.upper for p in free]) - lower)

    def to_z(self, theta) -> np.ndarray:
        theta = np.atleast_2d(np.asarray(theta, float))
        u = np.column_stack([self.priors.priors[n].cdf(theta[:, j]) for j, n in enumerate(self.names)])
        u = np.clip(u, _U_FLOOR, 1.0 - _U_FLOOR)
        return np.log(u) - np.log1p(-u)

    def to_theta(self, z):
        """theta for z (W, D); numpy in, numpy out; JAX in (traced), JAX out."""
        if isinstance(z, jax.Array):
            u = jax.nn.sigmoid(z)
            return jnp.stack([self.priors.priors[n].rescale(u[..., j]) for j, n in enumerate(self.names)], axis=-1)
        z = np.atleast_2d(np.asarray(z, float))
        u = 0.5 * (1.0 + np.tanh(0.5 * z))  # sigmoid without overflow
        if self._uniform is not None:  # every prior uniform: one vector operation (emcee calls this every step)
            lower, width = self._uniform
            return np.minimum(lower + width * u, lower + width)
        return np.column_stack([self.priors.priors[n].rescale(u[:, j]) for j, n in enumerate(self.names)])

    def ln_prior(self, z):
        """The declared priors' log density in z: sum of log sigmoid(z) + log sigmoid(-z) over the last axis."""
        xp = jnp if isinstance(z, jax.Array) else np
        a = xp.abs(z)
        return -xp.sum(a + 2.0 * xp.log1p(xp.exp(-a)), axis=-1)

    def log_prob(self, posterior):
        """The posterior's log density in z, vectorised over rows (what emcee calls)."""

        def log_prob_z(z):
            z = np.atleast_2d(z)
            return posterior.log_likelihood(self.to_theta(z)) + self.ln_prior(z)

        return log_prob_z

    def log_posterior_theta(self, z, log_prob_z) -> np.ndarray:
        """The log posterior in the declared parameters (as ``Posterior.log_prob``) from the z-space value."""
        theta = self.to_theta(np.reshape(z, (-1, z.shape[-1])))
        lp = np.reshape(log_prob_z, -1) - self.ln_prior(np.reshape(z, (-1, z.shape[-1]))) + self.priors.ln_prob(theta)
        return lp.reshape(np.shape(log_prob_z))


class DeclaredSpace(SamplingSpace):
    """The declared parameters themselves (the baseline the benchmarks compare with): z = theta."""

    name = "declared"

    def to_z(self, theta) -> np.ndarray:
        return np.atleast_2d(np.asarray(theta, float)).copy()

    def to_theta(self, z):
        return z if isinstance(z, jax.Array) else np.atleast_2d(np.asarray(z, float))

    def ln_prior(self, z):
        return self.priors.ln_prob(z)

    def log_prob(self, posterior):
        return posterior.log_prob
