"""Speed on real data (issue 11, item 6): the full NIST PTFE set, all 15 normalised Mueller elements and
the BRDF, `paper+polarized_diffuse`, in one process.

For one wavelength (1,824 geometries x 16 numbers) and all four jointly (7,296 x 16): the time to a
converged posterior (the sampler's stopping rule: 50 autocorrelation times, R-hat <= 1.01, ESS >= 400),
then the report (figures, InferenceData, LOO), against the issue's budgets (5 and 20 min); and what the
likelihood adds to the forward model: one log-posterior call for a half-ensemble of walkers against the
model's Mueller evaluation alone (median of repeats).

    python benchmarks/ptfe_speed.py [--wavelengths 0.633 all] [--seed 0]
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from spacepol import configure_process
from spacepol.infer.inversion import invert
from spacepol.infer.posterior import Posterior
from spacepol.io import read_measurements
from spacepol.paths import bundled
from spacepol.physics import Model
from spacepol.physics.spectral import SpectralModel
from spacepol.report.run_report import write_run_report

BUDGET_MIN = {"one": 5.0, "all": 20.0}


def posterior_for(which: str) -> Posterior:
    data = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv"))
    model = Model.from_string("paper+polarized_diffuse")
    if which == "all":
        model = SpectralModel(model, np.unique(data.wavelength_um))
    else:
        data = data.at_wavelength(float(which))
    return Posterior.build(data, model)  # default observables: the Mueller matrix and the BRDF


def per_call(posterior: Posterior, repeats: int = 15) -> tuple[float, float]:
    """(forward model's Mueller evaluation, whole log posterior) for half an ensemble of 20 walkers, s."""
    rng = np.random.default_rng(1)
    theta = posterior.priors.sample(rng, 20)
    lik = posterior.likelihood
    params = posterior.model_params(theta)
    forward, total = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        lik.model.evaluate(params, lik.geometry, mueller=True, check=False)
        t1 = time.perf_counter()
        posterior.log_prob(theta)
        total.append(time.perf_counter() - t1)
        forward.append(t1 - t0)
    return statistics.median(forward), statistics.median(total)


def main():
    configure_process(small_calls=True)  # as the command line runs: small calls on the calling thread
    parser = argparse.ArgumentParser()
    parser.add_argument("--wavelengths", nargs="+", default=["0.633", "all"])
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    print(f"machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} at the start")
    rows = []
    for which in args.wavelengths:
        posterior = posterior_for(which)
        forward, total = per_call(posterior)
        lik = posterior.likelihood
        print(f"[{which}] {len(lik.data)} geometries x {len(lik.observables)} channels, {posterior.ndim} parameters; "
              f"one call for 20 walkers: forward model {1e3 * forward:.1f} ms, log posterior {1e3 * total:.1f} ms "
              f"(likelihood adds {100 * (total / forward - 1):.0f} %)", flush=True)
        t0 = time.perf_counter()
        inv = invert(posterior, seed=args.seed, progress=False)
        sampled = time.perf_counter() - t0
        with tempfile.TemporaryDirectory() as tmp:
            write_run_report(inv, Path(tmp), "ptfe")
        wall = time.perf_counter() - t0
        d, info = inv.summary.diagnostics, inv.draws.info
        budget = BUDGET_MIN["all" if which == "all" else "one"]
        rows.append((which, wall, sampled, budget))
        print(f"[{which}] converged posterior in {sampled / 60:.1f} min (+ report {(wall - sampled) / 60:.1f} min = "
              f"{wall / 60:.1f} min; budget {budget:g} min, ratio {wall / 60 / budget:.2f}): {info['steps']} steps x "
              f"{info['walkers']} walkers, tau max {info['tau_max']:.0f}, R-hat max {d['rhat_max']:.4f}, ESS min "
              f"{d['ess_min']:.0f}, capped {info['capped']}; load average now {os.getloadavg()[0]:.2f}", flush=True)
    print("\nsummary (wall = sampling + report, one process):")
    for which, wall, sampled, budget in rows:
        print(f"  {which:>6s}: {wall / 60:5.1f} min of a {budget:g} min budget ({sampled / 60:.1f} min sampling)")


if __name__ == "__main__":
    main()
