"""Where the samplers move: each free parameter as the logit of its prior's CDF, unless it piles up at a bound.

    z_j = logit(F_j(theta_j)),    theta_j = F_j^-1(sigmoid(z_j))

In z every declared prior becomes exactly the standard logistic density, so

    log p(z | data) = log L(theta(z)) + sum_j [log sigmoid(z_j) + log sigmoid(-z_j)]

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from .._runtime import ensure_double_precision
from ..priors import Uniform
from .prior_set import PriorSet

_U_FLOOR = 1e-15  # a parameter exactly at a bound maps to a finite z (|z| <= 34.5)
_REACH = 5.0  # a bound where the log posterior is within this of the centre's is inside the posterior's reach


def reaching_a_bound(posterior, centre) -> list[str]:
    """The free parameters whose prior bound the posterior reaches: moved alone from ``centre`` (an optimum) to
    its lower or upper bound, the log posterior falls by less than 5 (one vectorised call of 2D + 1 rows).

    That is the pile-up case (a dielectric's k, where R depends on k^2 and the likelihood is flat towards
    k = 0), not the ridge case: moving k_s alone to 0 makes DOP 0 everywhere, so the wedge's parameters, whose
    density vanishes at the origin, keep the logit."""
    centre = np.asarray(centre, float)
    bounds = posterior.priors.bounds
    rows = np.repeat(centre[None, :], 2 * len(centre) + 1, axis=0)
    for j in range(len(centre)):
        rows[1 + 2 * j, j], rows[2 + 2 * j, j] = bounds[j]
    lp = posterior.log_prob(rows)
    if not np.isfinite(lp[0]):
        return []
    drop = lp[0] - np.maximum(lp[1::2], lp[2::2])
    return [n for n, d in zip(posterior.priors.names, drop) if d < _REACH]


class SamplingSpace:
    """The sampler's coordinates of a PriorSet's free parameters: the logit of each prior's CDF, except the
    parameters named in ``declared``, which keep their own values (numpy and JAX)."""

    family = "logit-cdf"

    def __init__(self, priors: PriorSet, declared=()):
        ensure_double_precision()  # its transforms are JAX code, wrong in float32 near the bounds
        self.priors = priors
        self.names = priors.names
        unknown = set(declared) - set(self.names)
        if unknown:
            raise ValueError(f"not free parameters: {', '.join(sorted(unknown))}")
        self.declared = [n for n in self.names if n in set(declared)]
        self._logit = np.array([n not in set(declared) for n in self.names])
        self._priors = [priors.priors[n] for n in self.names]
        # the logit columns under a Uniform prior, rescaled in one array operation (emcee calls to_theta every step)
        self._uniform = np.array([self._logit[j] and type(p) is Uniform for j, p in enumerate(self._priors)], bool)
        self._lower = np.array([p.lower if u else 0.0 for p, u in zip(self._priors, self._uniform)])
        self._width = np.array([p.upper - p.lower if u else 0.0 for p, u in zip(self._priors, self._uniform)])

    @property
    def name(self) -> str:
        """What the chain file records: the family, and the parameters kept in their declared coordinates."""
        return self.family + (f" except {','.join(self.declared)}" if self.declared else "")

    @classmethod
    def from_name(cls, priors: PriorSet, name: str) -> "SamplingSpace":
        """The space a chain file names (``name``), so a resumed chain continues in the coordinates it began in."""
        if name == DeclaredSpace.family:
            return DeclaredSpace(priors)
        _, _, rest = name.partition(" except ")
        return cls(priors, [n for n in rest.split(",") if n])

    def to_z(self, theta) -> np.ndarray:
        """Rows of declared parameters (W, D) to the sampling coordinates z: the logit of each prior's CDF, the
        parameters in ``declared`` as they are."""
        theta = np.atleast_2d(np.asarray(theta, float))
        z = theta.copy()
        for j, prior in enumerate(self._priors):
            if self._logit[j]:
                u = np.clip(prior.cdf(theta[:, j]), _U_FLOOR, 1.0 - _U_FLOOR)
                z[:, j] = np.log(u) - np.log1p(-u)
        return z

    def to_theta(self, z):
        """theta for z (..., D), e.g. walkers (W, D) or a chain (steps, walkers, D); a single vector (D,) gives
        (1, D). numpy in, numpy out; JAX in (traced), JAX out."""
        if isinstance(z, jax.Array):
            u = jax.nn.sigmoid(z)
            return jnp.stack([p.rescale(u[..., j]) if self._logit[j] else z[..., j] for j, p in enumerate(self._priors)],
                             axis=-1)
        z = np.atleast_2d(np.asarray(z, float))
        flat = z.reshape(-1, z.shape[-1])
        u = 0.5 * (1.0 + np.tanh(0.5 * flat))  # sigmoid without overflow
        theta = np.where(self._uniform, self._lower + self._width * u, flat)
        for j, p in enumerate(self._priors):
            if self._logit[j] and not self._uniform[j]:
                theta[:, j] = p.rescale(u[:, j])
        return theta.reshape(z.shape)

    def ln_prior(self, z):
        """The declared priors' log density in z (rows over the last axis): log sigmoid(z) + log sigmoid(-z) for
        a logit coordinate, the prior's own ln_prob (-inf outside its support) for a declared one."""
        if not isinstance(z, jax.Array):  # numpy: the logit columns at once
            z = np.asarray(z, float)
            a = np.abs(z[..., self._logit])
            total = -(a + 2.0 * np.log1p(np.exp(-a))).sum(axis=-1)
            for j in np.flatnonzero(~self._logit):
                total = total + self._priors[j].ln_prob(z[..., j])
            return total
        total = 0.0
        for j, prior in enumerate(self._priors):
            zj = z[..., j]
            if self._logit[j]:
                a = jnp.abs(zj)
                total = total - (a + 2.0 * jnp.log1p(jnp.exp(-a)))
            else:
                total = total + prior.ln_prob(zj)
        return total

    def log_prob(self, posterior):
        """The posterior's log density in z, vectorised over rows (what emcee calls)."""

        def log_prob_z(z):
            z = np.atleast_2d(z)
            lp = self.ln_prior(z)
            inside = np.isfinite(lp)
            return lp + posterior.log_likelihood(self.to_theta(z), inside)

        return log_prob_z

    def log_posterior_theta(self, z, log_prob_z) -> np.ndarray:
        """The log posterior in the declared parameters (as ``Posterior.log_prob``) from the z-space value."""
        flat = np.reshape(z, (-1, z.shape[-1]))
        lp = np.reshape(log_prob_z, -1) - self.ln_prior(flat) + self.priors.ln_prob(self.to_theta(flat))
        return lp.reshape(np.shape(log_prob_z))


class DeclaredSpace(SamplingSpace):
    """The declared parameters themselves (the baseline the benchmarks compare with): z = theta."""

    family = "declared"

    def __init__(self, priors: PriorSet):
        super().__init__(priors, declared=priors.names)

    @property
    def name(self) -> str:
        """The family alone: every parameter is kept in its declared coordinates."""
        return self.family
