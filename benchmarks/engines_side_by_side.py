"""The sampling engines side by side on one posterior: seconds to a converged posterior, effective draws per
second, and whether the posteriors agree.

    python benchmarks/engines_side_by_side.py [--set synthetic|ptfe] [--engines emcee nuts nested laplace] [--seed 0]

``synthetic``: the bundled 84-point set with a hidden effect (data/synthetic/hidden_effect.csv), the paper's model.
``ptfe``: NIST's PTFE at 0.633 um in the plane of incidence (15 Mueller elements and the BRDF), the paper's model.
Each engine runs through ``spacepol.invert`` with its defaults (emcee: until 50 tau, R-hat <= 1.01 and ESS >= 400;
nuts: 4 chains in blocks until the same targets; nested: nautilus, 3 replicates, ln Z with its error; laplace:
importance-corrected). Agreement against the first engine: the median differences in units of its posterior SD
(target < 0.1) and the ratio of 90 % interval widths (target within 10 %). Load printed before and after.
"""

import argparse
import os
import time

import numpy as np


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--set", choices=("synthetic", "ptfe"), default="synthetic")
    ap.add_argument("--engines", nargs="+", default=["emcee", "nuts", "nested", "laplace"])
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    import spacepol
    from spacepol.paths import bundled

    spacepol.configure_process(small_calls=True)
    print(f"load before: {os.getloadavg()[0]:.2f} (1-minute average, {os.cpu_count()} CPUs)")
    if args.set == "synthetic":
        data = spacepol.load(bundled("synthetic", "hidden_effect.csv"))
    else:
        data = spacepol.load(bundled("ptfe", "ptfe_mueller_brdf.csv"), wavelength_um=0.633, in_plane=True)
    print(f"set {args.set}: {len(data)} geometries, model paper")
    results = {}
    for name in args.engines:
        start = time.perf_counter()
        try:
            result = spacepol.invert(data, "paper", engine=name, seed=args.seed)
        except spacepol.SpacepolError as exc:
            print(f"{name:8s} refused: {exc}")
            continue
        seconds = time.perf_counter() - start
        d = result.diagnostics
        evidence = f", ln Z {result.log_evidence[0]:.3f} +- {result.log_evidence[1]:.3f}" if result.log_evidence else ""
        rhat = "n/a" if d.rhat_max is None else f"{d.rhat_max:.4f}"
        print(f"{name:8s} {seconds:8.1f} s  converged {d.converged}  R-hat {rhat}  ESS {d.ess_min:.0f}  "
              f"ESS/s {d.ess_min / seconds:.1f}{evidence}", flush=True)
        results[name] = result
    if len(results) < 2:
        return
    first, base = next(iter(results.items()))
    reference = base.samples(include_fixed=False)
    for name, result in list(results.items())[1:]:
        mine = result.samples(include_fixed=False)
        cells = []
        for p, draws in reference.items():
            shift = (np.median(mine[p]) - np.median(draws)) / np.std(draws)
            width = np.subtract(*np.percentile(mine[p], [95, 5])) / np.subtract(*np.percentile(draws, [95, 5]))
            cells.append(f"{p} {shift:+.3f} SD, width x{width:.3f}")
        print(f"{name} vs {first}: " + "; ".join(cells))
    print(f"load after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
