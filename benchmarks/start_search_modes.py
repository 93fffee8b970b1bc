"""Which mode the start-point search ends in, plain or with the noise levels profiled out (issue 24, item 5).

On NIST's PTFE at all four wavelengths with ``paper+polarized_diffuse`` (the command in docs/getting-started.md), every search
stream of ``modes.search_modes`` runs once as ``optimum.find_optimum`` (without profiling) and once as
``optimum.find_optimum_profiled`` (today's), for ``--seeds`` seeds x ``--streams`` streams; each line gives the
log posterior it ended at and the seconds it took, and the table counts the distinct modes (within
``modes.SAME_MODE_LOG_POSTERIOR``).

    python benchmarks/start_search_modes.py --seeds 3 --streams 3      # ~15 min on 2 cores
"""

from __future__ import annotations

import argparse
import os
import time
from types import SimpleNamespace

import numpy as np

from spacepol import configure_process


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--streams", type=int, default=3)
    parser.add_argument("--model", default="paper+polarized_diffuse")
    parser.add_argument("--evaluations", type=int, default=3000)  # what search_modes gives each search
    args = parser.parse_args()
    configure_process(small_calls=True)
    from spacepol.commands import model_for
    from spacepol.infer.modes import SAME_MODE_LOG_POSTERIOR
    from spacepol.infer.optimum import find_optimum, find_optimum_profiled
    from spacepol.infer.posterior import Posterior
    from spacepol.io import read_measurements
    from spacepol.paths import bundled

    print(f"load before: {os.getloadavg()[0]:.2f}")
    data = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv"))
    posterior = Posterior.build(data, model_for(SimpleNamespace(model=args.model, dispersion=None), data))
    print(f"PTFE, {len(data)} geometries, {posterior.likelihood.n_obs} numbers, {args.model}: {posterior.ndim} parameters")
    found = {"plain": [], "profiled": []}
    for seed in range(args.seeds):
        for stream_index, stream in enumerate(np.random.default_rng(seed).spawn(args.streams)):
            for label, search in (("plain", find_optimum), ("profiled", find_optimum_profiled)):
                rng = np.random.default_rng(stream.integers(2**63))  # the same stream for both searches
                start = time.perf_counter()
                value, _ = search(posterior, rng, args.evaluations)
                seconds = time.perf_counter() - start
                found[label].append((value, seconds))
                print(f"seed {seed} stream {stream_index} {label:>8s}: log posterior {value:12.1f} ({seconds:.0f} s)", flush=True)
    best = max(v for rows in found.values() for v, _ in rows)
    print(f"\nbest mode found by any search: {best:.1f}")
    for label, rows in found.items():
        values = np.array([v for v, _ in rows])
        modes = sorted({round(v) for v in values}, reverse=True)
        distinct = [m for i, m in enumerate(modes) if all(abs(m - o) >= SAME_MODE_LOG_POSTERIOR for o in modes[:i])]
        at_best = int(np.sum(best - values < SAME_MODE_LOG_POSTERIOR))
        print(f"{label:>8s}: {at_best} of {len(values)} searches in the best mode; {len(distinct)} distinct end points "
              f"({', '.join(f'{m:,}' for m in distinct)}); median {np.median([s for _, s in rows]):.0f} s per search")
    print(f"load after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
