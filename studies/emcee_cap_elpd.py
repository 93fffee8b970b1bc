"""Does diagnose's 8,000-step cap on an emcee refit buy a better ELPD-LOO on PTFE's oxide-layer ridge? (issue 24)

    python studies/emcee_cap_elpd.py [MODEL ...]

diagnose refits a changed model with emcee where its Laplace approximation is refused; on PTFE's oxide-layer models
those chains stop at the cap unconverged (R-hat 1.11-1.14) after 54-65 s. Here one chain per model (the walkers
diagnose starts: a small ball at the global multistart's optimum, DE moves in the logit-CDF space) is read at
2,000, 4,000, 8,000 and 16,000 steps, and its ELPD-LOO computed as ``inversion.invert`` computes it from the chain so
far (burn-in min(half, 3 tau), thinning tau / 2, at most 2,000 draws), with delta ELPD and its SE against
``paper+lambertian`` (diagnose's round-2 base). Default models: ``paper+lambertian+oxide_layer`` and
``paper+lambertian+oxide_layer+ggx`` (the round-2 winner and a round-3 candidate). The data: the 278-geometry PTFE
set of ``benchmarks/diagnose_rounds_speed.py``.
"""

import sys
import time

import numpy as np

STOPS = (2000, 4000, 8000, 16000)
MODELS = ("paper+lambertian+oxide_layer", "paper+lambertian+oxide_layer+ggx")


def main(models):
    from spacepol import configure_process

    configure_process(small_calls=True)
    import emcee

    from ridge_base import base_pointwise, ptfe_set
    from spacepol.criticism.candidate_fits import _build
    from spacepol.infer.engines.emcee_sampler import _moves, _tau, ball, default_walkers, reaching_a_bound
    from spacepol.infer.optimum import multistart
    from spacepol.infer.diagnostics import psis_loo
    from spacepol.infer.inference_data import batched
    from spacepol.infer.sampling_space import SamplingSpace
    from spacepol.physics import Model

    data = ptfe_set()
    base_loo = base_pointwise(data)

    def pointwise_loo(post, theta):
        return psis_loo(batched(post.log_prob_pointwise, theta, 256).T)[0]  # relative efficiency 1

    for spec in models:
        post = _build(data, Model.from_string(spec), None, None)
        rng = np.random.default_rng(1)
        _, centre = multistart(post, rng)
        walkers = default_walkers(post.ndim)
        post.likelihood.exact_sizes.add(walkers // 2)
        initial = ball(post, centre, walkers, rng)
        space = SamplingSpace(post.priors, declared=reaching_a_bound(post, np.median(initial, axis=0)))
        sampler = emcee.EnsembleSampler(walkers, post.ndim, space.log_prob(post), vectorize=True, moves=_moves())
        sampler.random_state = np.random.RandomState(1).get_state()
        state, start = space.to_z(initial), time.perf_counter()
        for stop in STOPS:
            state = sampler.run_mcmc(state, stop - sampler.iteration, progress=False)
            chain = space.to_theta(sampler.get_chain())
            tau = _tau(chain)
            finite = bool(np.all(np.isfinite(tau)))
            burn = int(min(stop // 2, np.ceil(3 * np.max(tau)))) if finite else stop // 2
            thin = max(1, int(0.5 * np.min(tau))) if finite else 1
            kept = chain[burn::thin].reshape(-1, post.ndim)
            kept = kept[:: max(1, int(np.ceil(len(kept) / 2000)))]
            loo = pointwise_loo(post, kept)
            diff = loo - base_loo
            print(f"{spec} at {stop} steps ({time.perf_counter() - start:.0f} s): tau_max {np.max(tau):.0f}, "
                  f"ELPD-LOO {loo.sum():.1f}, delta {diff.sum():+.1f} +- {np.sqrt(len(diff) * np.var(diff)):.1f}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:] or MODELS)
