"""NUTS (numpyro) on the compiled, differentiable likelihood: a gradient sampler beside emcee.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import sys
import time

import jax
import jax.numpy as jnp
import numpy as np

from ..differentiable import log_likelihood_function
from ..engine_result import EngineResult
from ..sampling_space import SamplingSpace
from ..engine_result import ESS_TARGET, RHAT_TARGET
from .base import SAMPLER, Engine


def _potential(posterior, space):
    """-log p(z | data): the likelihood's pure JAX function composed with the space's transform."""
    ll = log_likelihood_function(posterior)

    def potential(z):
        value = ll(space.to_theta(z[None, :])[0])
        return -(space.ln_prior(z) + jnp.where(jnp.isnan(value), -jnp.inf, value))

    return potential


def _block(mcmc, fields):
    """The draws of numpyro's last run, (chains, draws, D), and its extra fields, (chains, draws) each."""
    return (np.asarray(mcmc.get_samples(group_by_chain=True)),
            {f: np.asarray(v) for f, v in mcmc.get_extra_fields(group_by_chain=True).items()})


def sample_nuts(posterior, rng: np.random.Generator, chains: int = 4, warmup: int = 500, draws: int = 500,
                max_draws: int = 8000, target_accept: float = 0.8, initial=None, progress: bool = True,
                model_name: str = "", seed: int | None = None, rhat_target: float = RHAT_TARGET,
                ess_target: float = ESS_TARGET, space=None) -> EngineResult:
    """``space``: the coordinates the chains move in (default: the logit space, every parameter)."""
    from numpyro.infer import MCMC, NUTS

    from .emcee_sampler import starting_points, worst_rhat_ess

    start = time.perf_counter()
    space = space or SamplingSpace(posterior.priors)
    z0 = jnp.asarray(space.to_z(starting_points(posterior, rng, chains, initial)[0]))
    kernel = NUTS(potential_fn=_potential(posterior, space), dense_mass=True, target_accept_prob=target_accept)
    mcmc = MCMC(kernel, num_warmup=warmup, num_samples=draws, num_chains=chains, chain_method="vectorized",
                progress_bar=False)
    key = jax.random.PRNGKey(int(rng.integers(2**31)))
    fields = ("num_steps", "diverging", "potential_energy", "accept_prob")
    mcmc.run(key, init_params=z0, extra_fields=fields)
    blocks = [_block(mcmc, fields)]
    capped = True
    while True:
        z = np.concatenate([b[0] for b in blocks], axis=1)  # (chains, draws, D)
        rhat, ess = worst_rhat_ess(z)
        if progress:
            print(f"  NUTS: {z.shape[1]} draws x {chains} chains, R-hat {rhat:.3f}, ESS {ess:.0f}", file=sys.stderr)
        if rhat <= rhat_target and ess >= ess_target:
            capped = False
            break
        if z.shape[1] >= max_draws:
            break
        mcmc.post_warmup_state = mcmc.last_state  # more draws with the adapted step size and mass matrix
        mcmc.run(mcmc.post_warmup_state.rng_key, extra_fields=fields)
        blocks.append(_block(mcmc, fields))
    extra = {f: np.concatenate([b[1][f] for b in blocks], axis=1) for f in fields}
    z_draws = z.transpose(1, 0, 2)  # (draws, chains, D), the EngineResult's layout
    log_prob = space.log_posterior_theta(z_draws, -extra["potential_energy"].T)
    samples = space.to_theta(z_draws)
    best_i = np.unravel_index(np.argmax(log_prob), log_prob.shape)
    leapfrogs = int(extra["num_steps"].sum())
    info = {
        "steps": int(z.shape[1]), "walkers": chains, "chains": chains, "warmup": warmup, "burn_in": 0, "thin": 1,
        "acceptance": float(extra["accept_prob"].mean()), "capped": capped, "resumed": False,
        "leapfrog_per_draw": float(extra["num_steps"].mean()), "divergences": int(extra["diverging"].sum()),
        "space": space.name, "sampler": "nuts",
    }
    return EngineResult(
        method="nuts", model=model_name, names=list(posterior.names),
        best=dict(zip(posterior.names, map(float, samples[best_i]))), objective=float(-log_prob[best_i]),
        objective_name="negative_log_posterior", n_evaluations=leapfrogs, seconds=time.perf_counter() - start,
        seed=-1 if seed is None else seed, samples=samples, log_prob=log_prob, info=info,
    )


class Nuts(Engine):
    """numpyro's NUTS on the compiled, differentiable likelihood in the logit space, dense mass matrix, several
    chains, run in blocks until R-hat <= 1.01 and ESS >= 400 (or ``max_draws``)."""

    name, kind = "nuts", SAMPLER
    description = "No-U-Turn sampler (numpyro) on the differentiable likelihood"

    def run(self, posterior, rng, chains: int = 4, warmup: int = 500, draws: int = 500, max_draws: int = 8000,
            target_accept: float = 0.8, progress: bool = False):
        """NUTS draws (``engines.nuts.sample_nuts``)."""
        return sample_nuts(posterior, rng, chains=chains, warmup=warmup, draws=draws, max_draws=max_draws,
                           target_accept=target_accept, progress=progress, model_name=posterior.likelihood.model.name)
