"""PSIS over many observations: spacepol's vectorised smoothing (infer.psis) against ArviZ's psislw, its reference.

    python benchmarks/psis_speed.py [--repeats 5]

Sizes of diagnose's refits on the 278-geometry full-Mueller PTFE set: 4,448 numbers x 2,000 and x 8,000 importance
draws (log ratios drawn with tails like a Laplace-IS posterior's). The two run alternately in one process; prints
the median seconds of each, their ratio, the largest difference of the smoothed log weights and of Pareto k, and
the machine's load average before and after.
"""

import argparse
import os
import time

import arviz as az
import numpy as np

from spacepol.infer.psis import psis_log_weights


def main():
    from spacepol import configure_process

    configure_process()  # the settings the command line makes
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    load = os.getloadavg()
    rng = np.random.default_rng(0)
    for draws in (2000, 8000):
        # log ratios -log p(y_i | theta_s) + a weight: Student-t tails of varied width, so k spans ~0 to ~1
        x = rng.standard_t(rng.uniform(2.0, 30.0, (4448, 1)), size=(4448, draws)) * rng.uniform(0.1, 2.0, (4448, 1))
        ours, theirs = [], []
        for _ in range(args.repeats):
            t = time.perf_counter()
            a, ka = psis_log_weights(x)
            ours.append(time.perf_counter() - t)
            t = time.perf_counter()
            b, kb = az.psislw(x.copy(), reff=1.0)
            theirs.append(time.perf_counter() - t)
        b, kb = np.asarray(b), np.asarray(kb)
        print(f"4448 x {draws}: vectorised {np.median(ours):.2f} s, ArviZ {np.median(theirs):.2f} s, "
              f"ratio {np.median(theirs) / np.median(ours):.1f}; largest difference: log weights "
              f"{np.max(np.abs(a - b)):.1e}, k {np.max(np.abs(ka - kb)):.1e} (k from {kb.min():.2f} to {kb.max():.2f})")
    print(f"load average before/after {load[0]:.2f}/{os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
