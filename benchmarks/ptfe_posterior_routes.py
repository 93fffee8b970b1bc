"""Why the PTFE phase-matrix posterior is not reached in 10 min: what a gradient costs against a batched evaluation, and
whether emcee's walkers mix, from the default start and from a start shaped by the Laplace covariance.

On ``specular+smith+subsurface+phase_matrix`` at one wavelength (or all four jointly), whole hemisphere:

1. one log posterior for a batch of walkers (the emcee step's unit) against one value-and-gradient of the same log
   posterior in the logit space (NUTS's and L-BFGS's unit), compilation timed apart;
2. emcee from the search's optimum (the tight ball every run uses, and a start drawn from the Laplace covariance at the
   polished mode with its flat and negative directions floored), its integrated autocorrelation time read every 500
   steps. A chain that mixes has a tau estimate that settles; one that grows with the chain's length has not mixed.

    python benchmarks/ptfe_posterior_routes.py [--wavelength-um 0.633] [--steps 3000] [--no-gradient]
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "studies"))

from ptfe_models import load, model_for  # noqa: E402

from spacepol import configure_process  # noqa: E402
from spacepol.infer.engines.emcee_sampler import ball, default_walkers, sample_emcee  # noqa: E402
from spacepol.infer.laplace import mode_and_precision  # noqa: E402
from spacepol.infer.optimum import find_optimum_on_every  # noqa: E402
from spacepol.infer.posterior import Posterior  # noqa: E402
from spacepol.infer.sampling_space import SamplingSpace  # noqa: E402

MODEL = "specular+smith+subsurface+phase_matrix"


def gradient_cost(post: Posterior, rng) -> None:
    """Prints the batched evaluation's and the gradient's cost per parameter set."""
    import jax
    import jax.numpy as jnp

    from spacepol.infer.differentiable import log_likelihood_function

    walkers = default_walkers(post.ndim)
    theta = post.priors.sample(rng, walkers // 2)
    post.log_prob(theta)
    batch = statistics.median(_timed(lambda: post.log_prob(theta)) for _ in range(7))
    space = SamplingSpace(post.priors)
    ll = log_likelihood_function(post)
    value_and_grad = jax.jit(jax.value_and_grad(lambda z: -(space.ln_prior(z) + ll(space.to_theta(z[None, :])[0]))))
    z = jnp.asarray(space.to_z(theta))
    compile_s = _timed(lambda: value_and_grad(z[0])[1].block_until_ready())
    grad = statistics.median(_timed(lambda i=i: value_and_grad(z[i])[1].block_until_ready()) for i in range(1, 6))
    per_set = batch / len(theta)
    print(f"log posterior, batch of {len(theta)}: {batch * 1e3:.1f} ms ({per_set * 1e3:.2f} ms per set); value and "
          f"gradient: {grad * 1e3:.1f} ms per set ({grad / per_set:.0f}x), compiled in {compile_s:.0f} s", flush=True)


def laplace_start(post: Posterior, centre, walkers: int, rng) -> np.ndarray:
    """Walkers drawn from N(mode, cov / 4) in the logit space: cov the inverse Hessian at the polished mode, its
    eigenvalues floored at 1 (flat and negative directions get unit width)."""
    space = SamplingSpace(post.priors)
    mode, precision = mode_and_precision(space.log_prob(post), space.to_z(np.asarray(centre, float)[None])[0])
    values, vectors = np.linalg.eigh(0.5 * (precision + precision.T))
    print(f"  Hessian eigenvalues: {np.sum(values <= 0)} <= 0, smallest {values[:3].round(2)}, largest "
          f"{values[-1]:.3g}", flush=True)
    covariance = (vectors / np.maximum(values, 1.0)) @ vectors.T
    return space.to_theta(rng.multivariate_normal(mode, 0.25 * covariance, walkers))


def _timed(call) -> float:
    t0 = time.perf_counter()
    call()
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--wavelength-um", default="0.633", help="one wavelength, or 'all'")
    ap.add_argument("--steps", type=int, default=3000)
    ap.add_argument("--search-every", type=int, default=2)
    ap.add_argument("--no-gradient", action="store_true", help="skip the gradient's cost (its compilation is long)")
    args = ap.parse_args()
    configure_process()
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, load {os.getloadavg()}")
    data = load(args.wavelength_um)
    post = Posterior.build(data, model_for(data, MODEL))
    print(f"{MODEL} at {args.wavelength_um} um: {len(data)} geometries, {post.ndim} free parameters", flush=True)
    rng = np.random.default_rng(0)
    if not args.no_gradient:
        gradient_cost(post, rng)
    t0 = time.perf_counter()
    best, centre = find_optimum_on_every(post, args.search_every, np.random.default_rng(0), evaluations=3000)
    print(f"search: maximum {best:.1f} in {time.perf_counter() - t0:.0f} s", flush=True)
    walkers = default_walkers(post.ndim)
    for name, start in (("tight ball (the default)", lambda r: ball(post, centre, walkers, r)),
                        ("Laplace-shaped", lambda r: laplace_start(post, centre, walkers, r))):
        print(f"emcee, {walkers} walkers, {name} start:", flush=True)
        r = np.random.default_rng(1)
        t0 = time.perf_counter()
        result = sample_emcee(post, r, walkers=walkers, max_steps=args.steps, initial=start(r), progress=True,
                              check_every=500)
        print(f"  {time.perf_counter() - t0:.0f} s, capped {result.info['capped']}, load {os.getloadavg()}", flush=True)


if __name__ == "__main__":
    main()
