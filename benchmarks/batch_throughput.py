"""Batch throughput: the same sets inverted with 1 and with 2 local workers (and on a Dask LocalCluster of
2), in one process. Prints sets per minute, the speed-up of 2 workers over 1, and the load average.

    python benchmarks/batch_throughput.py [--sets 6]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np

from spacepol.batch import run_batch
from spacepol.io import write_table
from spacepol.physics import Model
from spacepol.physics.geometry import default_grid


def make_sets(folder: Path, count: int) -> Path:
    """``count`` DOP + BRDF sets of the paper's model (84 points) at different truths, and their manifest."""
    rng = np.random.default_rng(7)
    grid, model = default_grid(), Model.from_string("paper")
    rows = ["id,data,seed"]
    for i in range(count):
        truth = {"n": rng.uniform(1.2, 2.0), "k": rng.uniform(0, 2), "sigma": rng.uniform(0.1, 0.5),
                 "ks": rng.uniform(0.3, 0.9), "rho_d": rng.uniform(0.05, 0.4)}
        pred = model.evaluate(truth, grid)
        write_table(folder / f"set{i}.csv", {
            "theta_i": grid.theta_i, "theta_r": grid.theta_r, "dphi": grid.dphi,
            "dop": np.clip(pred.dop + 0.005 * rng.standard_normal(grid.size), 0, 1), "dop_err": np.full(grid.size, 0.005),
            "brdf": pred.brdf * (1 + 0.02 * rng.standard_normal(grid.size)), "brdf_err": 0.02 * pred.brdf})
        rows.append(f"set{i},set{i}.csv,{i}")
    (folder / "sets.csv").write_text("\n".join(rows) + "\n")
    return folder / "sets.csv"


def main():
    from spacepol import configure_process

    configure_process()  # the settings the command line makes
    parser = argparse.ArgumentParser()
    parser.add_argument("--sets", type=int, default=6)
    args = parser.parse_args()
    print(f"load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory() as tmp:
        manifest = make_sets(Path(tmp), args.sets)
        rates = {}
        for label, executor, workers in [("local, 1 worker", "local", 1), ("local, 2 workers", "local", 2),
                                         ("dask LocalCluster, 2 workers", "dask", 2)]:
            out = Path(tmp) / label.replace(" ", "_").replace(",", "")
            start = time.perf_counter()
            rows = run_batch(manifest, out, executor=executor, workers=workers, progress=False)
            wall = time.perf_counter() - start
            ok = sum(r["status"] == "ok" for r in rows)
            rates[label] = 60 * ok / wall
            print(f"  {label:30s} {wall:6.1f} s for {ok}/{len(rows)} sets: {rates[label]:5.1f} sets/min "
                  f"(worker start-up and compilation included)")
            start = time.perf_counter()
            run_batch(manifest, out, executor=executor, workers=workers, progress=False)
            print(f"  {'':30s} re-run (all skipped): {time.perf_counter() - start:.1f} s")
        print(f"2 workers over 1: {rates['local, 2 workers'] / rates['local, 1 worker']:.2f}x (local), "
              f"{rates['dask LocalCluster, 2 workers'] / rates['local, 1 worker']:.2f}x (Dask)")
    print(f"load average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
