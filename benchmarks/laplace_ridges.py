"""The Laplace engine on curved bands against emcee (issue 47, item 6): every posterior SD it returns is within 10 %
of emcee's (or wider), or it sampled with emcee and said so.

    python benchmarks/laplace_ridges.py [--seeds 1 2 3 4 5 6] [--brdf-noise 1.0 0.3]

The bands (``tests/ridges.py``): the paper's model on the 84 in-plane geometries of ``default_grid``, DOP (noise 0.005)
and a BRDF with relative noise ``--brdf-noise``, for a metal truth (the paper's aluminium, n 1.24, k 6.6) and a
dielectric one (n 1.5, k 0). Per truth and noise: emcee's posterior SDs once (seed 1, 50 autocorrelation times);
per seed, whether the importance weights' own checks (Pareto k, effective draws, width) trust the draws and their SD
over emcee's, their Pareto k (at most ``spread_check.BOUNDED_K``: the engine runs no walkers), what the walkers'
spread found (run here whatever k says), what the engine ran and the SDs it returned over emcee's.
"""

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from ridges import DIELECTRIC, METAL, band_posterior  # noqa: E402

from spacepol.infer.engine_registry import SAMPLER, engines  # noqa: E402
from spacepol.infer.inversion import invert  # noqa: E402
from spacepol.infer.laplace import laplace_importance  # noqa: E402
from spacepol.infer.optimum import find_optimum  # noqa: E402
from spacepol.infer.spread_check import BOUNDED_K, spread_check, weighted_sd  # noqa: E402


REFERENCE_TAUS = 250  # the reference chain: 5x emcee's default length, so its own SDs carry ~1/sqrt(5) the error


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 5, 6])
    ap.add_argument("--brdf-noise", type=float, nargs="+", default=[1.0, 0.3])
    args = ap.parse_args()
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.2f}")
    laplace = engines.get("laplace", SAMPLER)
    for truth_name, truth in (("metal", METAL), ("dielectric", DIELECTRIC)):
        for noise in args.brdf_noise:
            post = band_posterior(truth, noise)
            _, centre = find_optimum(post, np.random.default_rng(0))
            start = time.perf_counter()
            reference = invert(post, seed=1, progress=False, centre=centre, tau_multiple=REFERENCE_TAUS, max_steps=100000)
            exact = reference.draws.flat_samples().std(0)
            print(f"\n{truth_name}, BRDF noise {noise:g}: emcee SDs " + ", ".join(
                f"{n} {v:.3g}" for n, v in zip(post.names, exact)) + f" ({REFERENCE_TAUS} autocorrelation times, ESS "
                f"{reference.summary.diagnostics['ess_min']:.0f}, {time.perf_counter() - start:.0f} s)")
            print("| seed | weights' checks | Pareto k | IS SD / emcee (n, k) | walkers' growth (n, k) | ran | "
                  "returned SD / emcee, min | s |")
            print("|---|---|---|---|---|---|---|---|")
            for seed in args.seeds:
                sample = laplace_importance(post, centre, np.random.default_rng(seed))
                trusted = sample is not None and sample.reliable
                is_ratio = (weighted_sd(sample.theta, sample.log_weights)[:2] / exact[:2] if sample is not None
                            else [np.nan, np.nan])
                growth = (spread_check(post, sample, np.random.default_rng(seed).spawn(1)[0],
                                       skip_bounded=False).ratios[:2] if trusted else [np.nan, np.nan])
                k = sample.pareto_k if sample is not None else np.nan
                bounded = " (bounded: no walkers)" if k <= BOUNDED_K else ""
                start = time.perf_counter()
                result = laplace.result(post, seed=seed)
                ran = result.summary.diagnostics["engine"]
                ratio = result.draws.flat_samples().std(0) / exact
                print(f"| {seed} | {'trusted' if trusted else 'refused'} | {k:.2f}{bounded} | "
                      f"{is_ratio[0]:.2f}, {is_ratio[1]:.2f} | "
                      f"{growth[0]:.2f}, {growth[1]:.2f} | {ran} | {ratio.min():.2f} ({post.names[int(np.argmin(ratio))]}) | "
                      f"{time.perf_counter() - start:.0f} |", flush=True)


if __name__ == "__main__":
    main()
