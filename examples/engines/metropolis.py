"""A user's sampler in one file: random-walk Metropolis, to show the engine interface.

    invert-mcmc run data.csv --engine examples/engines/metropolis.py:RandomWalk --out runs/rw
    spacepol.invert(data, "paper", engine="examples/engines/metropolis.py:RandomWalk")

An engine subclasses ``Engine`` and returns draws (draws x chains x parameters, in ``posterior.names`` order) with
their log posterior; spacepol makes the Result (ArviZ groups, R-hat and ESS, PSIS-LOO, the report). This one is
simple on purpose: independent chains from prior draws, a Gaussian proposal shaped by the chains' covariance during
the first half (then frozen, so the second half is a valid Markov chain), the second half kept.
"""

import time

import numpy as np

from spacepol.infer.engine_result import EngineResult
from spacepol.infer.engines.base import Engine


class RandomWalk(Engine):
    """Random-walk Metropolis with a proposal adapted in the first half of the run."""

    name = "random_walk"
    description = "random-walk Metropolis (an example plug-in engine)"

    def run(self, posterior, rng, chains: int = 8, steps: int = 6000, progress: bool = False):
        """``chains`` chains of ``steps`` steps; the second half is returned."""
        start = time.perf_counter()
        x = posterior.priors.sample(rng, chains)
        lp = posterior.log_prob(x)
        scale = np.diag(np.var(x, axis=0) + 1e-12) * 2.38**2 / posterior.ndim
        kept, kept_lp, accepted = [], [], 0
        for step in range(steps):
            if step < steps // 2 and step % 200 == 199:  # adapt on the chains' recent spread, then freeze
                recent = np.concatenate(kept[-200:]) if kept else x
                scale = np.cov(recent.T).reshape(posterior.ndim, posterior.ndim) * 2.38**2 / posterior.ndim
                scale += np.eye(posterior.ndim) * 1e-12
                kept.clear()
            proposal = x + rng.multivariate_normal(np.zeros(posterior.ndim), scale, size=chains)
            lp_new = posterior.log_prob(proposal)
            accept = np.log(rng.random(chains)) < lp_new - lp
            x = np.where(accept[:, None], proposal, x)
            lp = np.where(accept, lp_new, lp)
            if step >= steps // 2:
                accepted += int(accept.sum())
            kept.append(x.copy())
            kept_lp.append(lp.copy())
        half = steps - steps // 2
        samples, log_prob = np.stack(kept[-half:]), np.stack(kept_lp[-half:])  # (draws, chains, D), (draws, chains)
        best = samples.reshape(-1, posterior.ndim)[int(np.argmax(log_prob))]
        return EngineResult(method=self.name, model=posterior.likelihood.model.name, names=list(posterior.names),
                            best=dict(zip(posterior.names, map(float, best))), objective=-float(log_prob.max()),
                            objective_name="negative_log_posterior", n_evaluations=steps * chains,
                            seconds=time.perf_counter() - start, seed=-1, samples=samples, log_prob=log_prob,
                            info={"chains": chains, "steps": steps, "acceptance": accepted / (half * chains)})
