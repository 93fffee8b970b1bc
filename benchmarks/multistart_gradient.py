"""The multistart's polish by exact JAX gradients against batched finite differences, in one process: PTFE at four
wavelengths, every 8th row, the study's phase-matrix model with its noise levels profiled (what the study's global
search climbs), the same Sobol points for both. Prints each one's time (the gradient's compilation included) and
maximum, with the machine and load.

    python benchmarks/multistart_gradient.py [--every 8] [--seed 7]
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

from spacepol.infer.optimum import multistart
from spacepol.infer.posterior import Posterior
from spacepol.infer.profiled import ProfiledPosterior

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "studies"))
import ptfe_models  # noqa: E402

SPEC = ("specular+smith+subsurface+phase_matrix [w_pm=1 dl_pm=0 fc_pm=0 pm_m44_0=1 pm_m44_180=1 "
        "k@0.351=0 k@0.532=0 k@0.633=0 k@1.064=0 ks=1]")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--every", type=int, default=8)
    parser.add_argument("--seed", type=int, default=7)
    args = parser.parse_args(argv)
    data = ptfe_models.load("all")
    data.mueller_noise_profile = ptfe_models.measured_noise_profile(data, ptfe_models.measured_noise(data))
    model = ptfe_models.model_for(data, SPEC)
    post = Posterior.build(data, model, prior_overrides=ptfe_models.entry_priors(model, SPEC))
    coarse = ProfiledPosterior.of(post.on_rows(np.arange(0, len(data), args.every)))
    print(f"PTFE, four wavelengths, every {args.every}th row: {coarse.likelihood.n_obs} numbers, {coarse.ndim} parameters "
          f"(levels profiled); {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"load {os.getloadavg()[0]:.2f}", flush=True)
    coarse.log_prob(coarse.priors.rescale(np.random.default_rng(0).random((16, coarse.ndim))))  # compiled before both
    for gradient in (True, False):
        start = time.perf_counter()
        best, _ = multistart(coarse, np.random.default_rng(args.seed), gradient=gradient)
        print(f"  {'exact gradients' if gradient else 'finite differences'}: {time.perf_counter() - start:.0f} s, "
              f"maximum {best:.1f}; load {os.getloadavg()[0]:.2f}", flush=True)


if __name__ == "__main__":
    main()
