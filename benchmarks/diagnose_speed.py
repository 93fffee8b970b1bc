"""How long `diagnose` takes on an 84-point set with the whole effect library (issue 4: <= 3 min).

    python benchmarks/diagnose_speed.py [--repeats 3]

Runs diagnose (paper model, every registered effect that composes with it) on the bundled
hidden-effect set (84 in-plane points, DOP + BRDF) `repeats` times with different seeds in this
one process and prints the median and range of the wall time, split into base fit, screening and
confirmation, against the 180 s budget.
"""

import argparse
import time

import numpy as np

from spacepol.criticism.diagnose import diagnose
from spacepol.io import read_measurements
from spacepol.paths import bundled
from spacepol.physics import Model


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    data = read_measurements(bundled("synthetic", "hidden_effect.csv"))
    rows = []
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
    print(f"{len(data)} points, whole library: median {np.median(wall):.1f} s (range {wall.min():.1f}-{wall.max():.1f}); "
          f"budget 180 s; ratio {np.median(wall) / 180:.2f}")


if __name__ == "__main__":
    main()
