"""Time to a converged posterior: an 84-point DOP set, the `paper` model, emcee, in one process.

Converged means the sampler's own stopping rule: chain longer than 50 integrated
autocorrelation times, R-hat <= 1.01 and ESS >= 400 for every parameter (walkers as chains).
Prints the wall time (median over seeds), ESS per second, and the paper's GA run on the same
data: wall time, evaluations and its eq-25 objective, side by side.

    python benchmarks/inversion_speed.py [--seeds 3]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from spacepol.infer.engines import optimize
from spacepol.infer.inversion import invert
from spacepol.infer.objective import PaperObjective
from spacepol.infer.posterior import Posterior
from spacepol.infer.prior_set import PriorSet
from spacepol.io.measurements import Dataset
from spacepol.physics import Model
from spacepol.physics.geometry import default_grid

TRUTH = {"n": 1.24, "k": 6.6, "sigma": 0.2, "ks": 0.5, "rho_d": 0.1}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--seeds", type=int, default=3)
    args = parser.parse_args()
    model = Model.from_string("paper")
    g = default_grid()
    rng = np.random.default_rng(0)
    data = Dataset(g.theta_i, g.theta_r, g.dphi)
    data.dop = np.clip(model.evaluate(TRUTH, data.geometry).dop + 0.005 * rng.standard_normal(g.size), 0, 1)
    data.dop_err = np.full(g.size, 0.005)
    posterior = Posterior.build(data, model)
    invert(posterior, seed=99, max_steps=200, progress=False)  # warm-up: compile kernels, import ArviZ

    walls, ess_rates, rows = [], [], []
    for seed in range(args.seeds):
        t0 = time.perf_counter()
        inv = invert(posterior, seed=seed, progress=False)
        wall = time.perf_counter() - t0
        d = inv.summary["diagnostics"]
        walls.append(wall)
        ess_rates.append(d["ess_min"] / wall)
        rows.append(f"  seed {seed}: {wall:6.1f} s, {inv.result.info['steps']} steps x {inv.result.info['walkers']} walkers, "
                    f"R-hat max {d['rhat_max']:.4f}, ESS min {d['ess_min']:.0f}, capped {inv.result.info['capped']}")
    ga_walls, ga_evals, ga_obj = [], [], []
    objective = PaperObjective(data, model, PriorSet(model.parameters))
    for seed in range(args.seeds):
        res = optimize("ga", objective, np.random.default_rng(seed), model.name)
        ga_walls.append(res.seconds)
        ga_evals.append(res.n_evaluations)
        ga_obj.append(res.objective)
    truth_obj = float(objective(np.array([[TRUTH[n] for n in objective.names]]))[0])
    print(f"paper model, {g.size}-point DOP set (noise 0.005), {args.seeds} seeds")
    print("\n".join(rows))
    print(f"emcee to a converged posterior: median {statistics.median(walls):.1f} s wall "
          f"(target <= 15 s); ESS (min over parameters) per second: median {statistics.median(ess_rates):.0f}")
    print(f"paper's GA: median {statistics.median(ga_walls):.2f} s wall, {statistics.median(ga_evals):.0f} evaluations, "
          f"eq-25 objective median {statistics.median(ga_obj):.5f} (the truth scores {truth_obj:.5f}); "
          f"a point, no uncertainty")


if __name__ == "__main__":
    main()
