"""diagnose's fits: a Laplace approximation corrected by importance sampling against emcee, on a real set.

    python benchmarks/laplace_vs_emcee.py [--models paper paper+lambertian ...] [--wavelength 0.633] [--seed 0]

The set: NIST's PTFE (data/ptfe) at one wavelength, every k-th geometry plus every reciprocal pair (as
``diagnose_rounds_speed.py``): 15 normalised Mueller elements and the BRDF per geometry. For each model, from one
optimum: ``invert_laplace`` (2,000 Student-t draws at the mode, PSIS weights) and ``invert`` with emcee as diagnose
ran it (20 tau, R-hat <= 1.01, ESS >= 400). Prints per model the seconds of each, the weights' Pareto k and
effective draws, the posterior means' differences and the SD ratios (in emcee's SDs), the ELPD-LOO of each and the
standard error of their pointwise difference, and E[-2 (log p - log p_mode)] of each posterior's draws (D for a
Gaussian posterior in the sampling space; it caught emcee's snooker move, ``engines/snooker.py``). Load printed.
"""

import argparse
import os
import time

import numpy as np


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--models", nargs="+", default=["paper", "paper+lambertian", "paper+polarized_diffuse"])
    ap.add_argument("--wavelength", type=float, default=0.633)
    ap.add_argument("--size", type=int, default=260)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    from spacepol import configure_process

    configure_process(small_calls=True)  # as the command line runs
    from spacepol.criticism.candidate_fits import ELPD_DRAWS, ELPD_TAU_MULTIPLE
    from spacepol.infer.inversion import invert, invert_laplace
    from spacepol.infer.measured_noise import reciprocal_pairs
    from spacepol.infer.optimum import find_optimum
    from spacepol.infer.posterior import Posterior
    from spacepol.infer.sampling_space import SamplingSpace
    from spacepol.io import read_measurements
    from spacepol.paths import bundled
    from spacepol.physics import Model

    load = os.getloadavg()
    first = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv")).at_wavelength(args.wavelength)
    rows = np.union1d(np.arange(0, len(first), max(1, len(first) // args.size)), reciprocal_pairs(first).ravel())
    data = first.select(rows)
    print(f"PTFE at {args.wavelength} um: {len(data)} geometries, {16 * len(data)} numbers")
    for name in args.models:
        post = Posterior.build(data, Model.from_string(name))
        rng = np.random.default_rng(args.seed)
        _, centre = find_optimum(post, rng)
        start = time.perf_counter()
        approx = invert_laplace(post, centre, seed=args.seed, draws=ELPD_DRAWS)
        t_laplace = time.perf_counter() - start
        start = time.perf_counter()
        exact = invert(post, seed=args.seed, progress=False, centre=centre, tau_multiple=ELPD_TAU_MULTIPLE,
                       max_pointwise_draws=ELPD_DRAWS)
        t_emcee = time.perf_counter() - start
        space = SamplingSpace(post.priors)
        log_prob_z = space.log_prob(post)
        e = exact.draws.flat_samples()
        peak = log_prob_z(space.to_z(e)).max()
        print(f"{name} ({post.ndim} parameters): emcee {t_emcee:.1f} s ({exact.draws.info['steps']} steps, "
              f"R-hat {exact.summary.diagnostics['rhat_max']:.4f}), E[-2 dlogp] {np.mean(-2 * (log_prob_z(space.to_z(e)) - peak)):.2f}")
        if approx is None:
            print(f"  Laplace-IS: not trusted here (Pareto k > 0.7 or too few effective draws): diagnose uses emcee "
                  f"({t_laplace:.1f} s spent finding out)")
            continue
        a = approx.draws.flat_samples()
        d = approx.summary.diagnostics
        shift = (a.mean(0) - e.mean(0)) / e.std(0)
        ratio = a.std(0) / e.std(0)
        diff = approx.loo["pointwise"] - exact.loo["pointwise"]
        print(f"  Laplace-IS {t_laplace:.1f} s (ratio to emcee {t_laplace / t_emcee:.3f}): Pareto k {d['pareto_k']:.2f}, "
              f"{d['ess_min']:.0f} effective draws, E[-2 dlogp] {np.mean(-2 * (log_prob_z(space.to_z(a)) - peak)):.2f}")
        print(f"  means differ by {np.max(np.abs(shift)):.2f} emcee SD at most; SD ratio {ratio.min():.3f}-{ratio.max():.3f}")
        print(f"  ELPD-LOO Laplace-IS {approx.loo['elpd_loo']:.1f}, emcee {exact.loo['elpd_loo']:.1f}: "
              f"difference {diff.sum():+.1f} +- {np.sqrt(len(diff) * np.var(diff)):.1f}")
    print(f"load average before/after {load[0]:.2f}/{os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
