"""How long one `diagnose` round takes on an 84-point set with the whole effect library.

Targets: issue 4 <= 180 s, issue 10 <= 60 s, issue 12 <= 30 s.

    python benchmarks/diagnose_speed.py [--repeats 3]

Runs diagnose (paper model, every registered effect that composes with it) on the bundled
hidden-effect set (84 in-plane points, DOP + BRDF) `repeats` times with different seeds in this
one process and prints the median and range of the wall time, split into base fit, screening and
confirmation, against those budgets. Prints the machine's load average (the machine is shared).
"""

import argparse
import os
import time

import numpy as np

from spacepol import configure_process
from spacepol.criticism.diagnose import diagnose
from spacepol.io import read_measurements
from spacepol.paths import bundled
from spacepol.physics import Model


def main():
    configure_process(small_calls=True)  # as the command line runs: small calls on the calling thread
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    data = read_measurements(bundled("synthetic", "hidden_effect.csv"))
    rows, load = [], os.getloadavg()
    for seed in range(args.repeats):
        start = time.perf_counter()
        report = diagnose(data, Model.from_string("paper"), np.random.default_rng(seed), seed=seed, progress=False)
        wall = time.perf_counter() - start
        s = report["seconds"]
        rows.append((wall, s["base_fit"], s["screening"], s["confirmation"]))
        print(f"seed {seed}: {wall:6.1f} s (base fit {s['base_fit']:.1f}, screening {s['screening']:.1f} for "
              f"{s['candidates_screened']} effects, confirmation {s['confirmation']:.1f} for {s['candidates_refitted']}); "
              f"verdict {report['verdict']}", flush=True)
    wall = np.array([r[0] for r in rows])
    budgets = ", ".join(f"{b} s (issue {i}): ratio {np.median(wall) / b:.2f}" for i, b in ((4, 180), (10, 60), (12, 30)))
    print(f"{len(data)} points, whole library, one round: median {np.median(wall):.1f} s "
          f"(range {wall.min():.1f}-{wall.max():.1f}); budgets {budgets}; load average before/after "
          f"{load[0]:.2f}/{os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
