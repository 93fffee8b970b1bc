"""What a likelihood call costs per parameter set by the size of the call, on the bundled 84-point DOP + BRDF set
(``paper``): the figures behind ``infer.likelihood``'s block rule (one compiled block of 16 sets, a block of 256 only
once a likelihood has evaluated enough sets in large calls to pay for its compilation). Medians of repeats after a
warm-up call; the compilation of each new block size is timed apart (the first call).

    python benchmarks/likelihood_blocks.py [--repeats 20]
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

import numpy as np

import spacepol
from spacepol.infer import likelihood_blocks
from spacepol.infer.posterior import Posterior
from spacepol.paths import bundled
from spacepol.physics import Model


def per_set_us(post, theta, repeats: int) -> tuple[float, float]:
    """(first call s, median us per set) of ``post.log_prob`` on ``theta``."""
    start = time.perf_counter()
    post.log_prob(theta)
    first = time.perf_counter() - start
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        post.log_prob(theta)
        times.append(time.perf_counter() - start)
    return first, statistics.median(times) / len(theta) * 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20)
    args = parser.parse_args()
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}")
    data = spacepol.load(bundled("synthetic", "hidden_effect.csv"))
    theta_all = None
    for label, large in (("blocks of 16 only (a fresh likelihood)", False), ("with the block of 256 (after enough large calls)", True)):
        post = Posterior.build(data, Model.from_string("paper"))
        theta_all = post.priors.rescale(np.random.default_rng(0).random((4096, post.ndim)))
        # the count of sets in large calls that switches the block of 256 on, set so that each table shows one rule
        post.likelihood._sets_in_large_calls = likelihood_blocks.SETS_PAYING_A_COMPILATION if large else -10**12
        print(f"\n{label}: compiled sizes {post.likelihood._compiled_sizes()}")
        print("| sets per call | first call (s) | us per set |\n|---|---|---|")
        for n in (16, 64, 256, 1024, 4096):
            first, us = per_set_us(post, theta_all[:n], args.repeats)
            print(f"| {n} | {first:.3f} | {us:.1f} |")
    print(f"\nload after {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
