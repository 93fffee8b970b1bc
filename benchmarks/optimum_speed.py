"""The global maximum of the log posterior: differential evolution against multistart L-BFGS, in one process.

Three searches on the same posterior, each from a fixed seed:
* DE: scipy's differential evolution on the prior cube (4,000 evaluations, popsize 10, finite-difference
  L-BFGS-B polish), as ``infer.optimum.find_optimum`` runs it;
* multistart, finite differences: 8,192 Sobol points, the best 8 polished by L-BFGS-B with batched
  forward differences (D + 1 rows per gradient);
* multistart, JAX gradients: the same starts, L-BFGS-B with the exact gradient of the compiled posterior.
Success: within 0.5 of the best log posterior any search found on that set. Times exclude compilation
(one warm-up call of each first). Sets: the 84-point DOP set (the k_s/rho_d ridge), the bundled 84-point
DOP+BRDF set, a DOP+BRDF set with a 0.25 um oxide film (a comb of interference orders), and with
``--sets ... ptfe`` the PTFE Mueller set at 0.633 um.

    python benchmarks/optimum_speed.py [--seeds 5] [--sets dop bundled bundled-rich film ptfe ptfe-in-plane]

``ptfe-in-plane``: PTFE's in-plane rows with the models diagnose --rounds searches there (up to 37 parameters);
``bundled-rich``: the 84-point set with a phase-matrix model (more parameters, few numbers).
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

from spacepol import configure_process

configure_process(small_calls=True)  # as the command line runs

from spacepol.infer.engines.de import run_de  # noqa: E402
from spacepol.infer.objective import NegativeLogPosterior  # noqa: E402
from spacepol.infer.optimum import multistart  # noqa: E402
from spacepol.infer.posterior import Posterior  # noqa: E402
from spacepol.io.measurements import Dataset, read_measurements  # noqa: E402
from spacepol.paths import bundled  # noqa: E402
from spacepol.physics import Model  # noqa: E402
from spacepol.physics.geometry import default_grid  # noqa: E402


def synthetic(spec, truth, brdf=True, wavelength_um=None, seed=0):
    model = Model.from_string(spec)
    g = default_grid()
    rng = np.random.default_rng(seed)
    data = Dataset(g.theta_i, g.theta_r, g.dphi, None if wavelength_um is None else np.full(g.size, wavelength_um))
    pred = model.evaluate(truth, data.geometry)
    data.dop = pred.dop + 0.005 * rng.standard_normal(g.size)
    data.dop_err = np.full(g.size, 0.005)
    if brdf:
        data.brdf = pred.brdf * (1 + 0.03 * rng.standard_normal(g.size))
        data.brdf_err = 0.03 * pred.brdf
    return data


def sets(chosen):
    if "dop" in chosen:
        data = synthetic("paper", {"n": 1.24, "k": 6.6, "sigma": 0.2, "ks": 0.5, "rho_d": 0.1}, brdf=False)
        yield "84-point DOP, paper", Posterior.build(data, Model.from_string("paper"))
    if "bundled" in chosen:
        data = read_measurements(bundled("synthetic", "hidden_effect.csv"))
        yield "bundled hidden_effect.csv, paper", Posterior.build(data, Model.from_string("paper"))
    if "film" in chosen:
        film = "paper+oxide_layer"
        data = synthetic(film, {"n": 1.2, "k": 7.0, "sigma": 0.15, "ks": 0.8, "rho_d": 0.05, "thickness_um": 0.25,
                                "n_film": 1.65}, wavelength_um=0.633)
        yield "0.25 um film, paper+oxide_layer", Posterior.build(data, Model.from_string(film))
    if "ptfe-in-plane" in chosen:  # the models diagnose --rounds searches on PTFE (its leaders' multistarts)
        data = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv")).at_wavelength(0.633).in_plane()
        for spec in ("paper", "paper+phase_matrix",
                     "specular+shadowing+polarized_diffuse+phase_matrix+polarization_memory+volume"):
            yield f"PTFE 0.633 um in-plane Mueller + BRDF, {spec}", Posterior.build(data, Model.from_string(spec))
    if "bundled-rich" in chosen:
        data = read_measurements(bundled("synthetic", "hidden_effect.csv"))
        yield "bundled hidden_effect.csv, paper+phase_matrix", Posterior.build(data, Model.from_string("paper+phase_matrix"))
    if "ptfe" in chosen:
        data = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv")).at_wavelength(0.633)
        yield "PTFE 0.633 um Mueller + BRDF, paper+polarized_diffuse", Posterior.build(
            data, Model.from_string("paper+polarized_diffuse"))


def de(posterior, rng):
    res = run_de(NegativeLogPosterior(posterior), rng, max_evaluations=4000, popsize=10, polish=True)
    return -res.objective


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--sets", nargs="+", choices=["dop", "bundled", "bundled-rich", "film", "ptfe", "ptfe-in-plane"], default=["dop", "bundled", "film"])
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.2f} (2 cores)")
    searches = {
        "DE (4,000 evaluations)": de,
        "multistart, finite differences": lambda p, rng: multistart(p, rng, gradient=False)[0],
        "multistart, JAX gradients": lambda p, rng: multistart(p, rng, gradient=True)[0],
        "multistart, automatic choice": lambda p, rng: multistart(p, rng, gradient=None)[0],
    }
    for label, posterior in sets(args.sets):
        print(f"\n{label}: {posterior.ndim} parameters, {posterior.likelihood.n_obs} numbers")
        for search in searches.values():  # warm-up: compile every program the searches use
            search(posterior, np.random.default_rng(1000))
        found = {}
        for name, search in searches.items():
            found[name] = []
            for seed in range(args.seeds):
                t0 = time.perf_counter()
                value = search(posterior, np.random.default_rng(seed))
                found[name].append((time.perf_counter() - t0, value))
        best = max(v for rows in found.values() for _, v in rows)
        for name, rows in found.items():
            hits = sum(v >= best - 0.5 for _, v in rows)
            print(f"  {name:32s} median {statistics.median(t for t, _ in rows):6.2f} s, reached the best "
                  f"({best:.1f}) {hits}/{len(rows)}; worst {min(v for _, v in rows):.1f}")
    print(f"\nload average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
