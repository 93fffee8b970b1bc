"""Time and ESS per second to a converged posterior, engines side by side, in one process.

Sets: an 84-point synthetic DOP set (the k_s/rho_d ridge: DOP sees only their ratio), the bundled
84-point set `data/synthetic/hidden_effect.csv` (DOP and BRDF), and with ``--sets ... ptfe`` the PTFE full-Mueller
set at 0.633 um (the Mueller matrix and the BRDF, the CLI's default observables). Model `paper` (PTFE: paper+polarized_diffuse).

Engines, each to the same stopping rule (ArviZ rank-normalised split R-hat <= 1.01 and bulk/tail ESS >= 400):
* emcee in the declared parameters (the baseline: what spacepol did before the logit space),
* emcee in the logit of each prior's CDF (the default; ``infer.sampling_space``), emcee also needing
  50 integrated autocorrelation times,
* NUTS (numpyro, dense mass matrix, 4 chains vectorised) in the same logit space; its first run includes
  JAX compilation (printed apart), the seeds after it reuse the compiled sampler,
* NUTS in the declared parameters (``nuts-declared``: the same sampler without the reparameterisation; its walls
  are the priors' bounds, the k_s/rho_d wedge stays a wedge).
Times are whole ``invert`` calls for emcee (optimum, sampling, ArviZ, LOO, checks) and the sampler alone for
NUTS, so the NUTS figures flatter it slightly. Plus the paper's GA on the 84-point set (a point, no uncertainty).

    python benchmarks/inversion_speed.py [--seeds 3] [--sets dop bundled ptfe] [--engines declared emcee nuts nuts-declared]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

from spacepol import configure_process

configure_process(small_calls=True)  # as the command line runs

from spacepol.infer.engine_registry import optimize  # noqa: E402
from spacepol.infer.engines.nuts import sample_nuts  # noqa: E402
from spacepol.infer.inversion import invert  # noqa: E402
from spacepol.infer.objective import PaperObjective  # noqa: E402
from spacepol.infer.posterior import Posterior  # noqa: E402
from spacepol.infer.prior_set import PriorSet  # noqa: E402
from spacepol.infer.sampling_space import DeclaredSpace, SamplingSpace  # noqa: E402
from spacepol.io.measurements import Dataset, read_measurements  # noqa: E402
from spacepol.paths import bundled  # noqa: E402
from spacepol.physics import Model  # noqa: E402
from spacepol.physics.geometry import default_grid  # noqa: E402

TRUTH = {"n": 1.24, "k": 6.6, "sigma": 0.2, "ks": 0.5, "rho_d": 0.1}


def dop_set():
    model = Model.from_string("paper")
    g = default_grid()
    rng = np.random.default_rng(0)
    data = Dataset(g.theta_i, g.theta_r, g.dphi)
    data.dop = np.clip(model.evaluate(TRUTH, data.geometry).dop + 0.005 * rng.standard_normal(g.size), 0, 1)
    data.dop_err = np.full(g.size, 0.005)
    data.source = "synthetic 84-point DOP"
    return Posterior.build(data, model)


def bundled_set():
    data = read_measurements(bundled("synthetic", "hidden_effect.csv"))
    return Posterior.build(data, Model.from_string("paper"))


def ptfe_set():
    data = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv")).at_wavelength(0.633)
    return Posterior.build(data, Model.from_string("paper+polarized_diffuse"))  # the Mueller matrix and the BRDF


def run_emcee(posterior, seed, space):
    t0 = time.perf_counter()
    inv = invert(posterior, seed=seed, progress=False, space=space)
    wall = time.perf_counter() - t0
    d, info = inv.summary.diagnostics, inv.draws.info
    return wall, d["ess_min"], d["rhat_max"], (f"{info['steps']} steps x {info['walkers']} walkers, tau_max "
                                               f"{info['tau_max']:.0f}, space {info['space']}"), info["capped"]


def run_nuts(posterior, seed, **options):
    from spacepol.infer.diagnostics import convergence
    from spacepol.infer.inference_data import to_inference_data

    t0 = time.perf_counter()
    res = sample_nuts(posterior, np.random.default_rng(seed), progress=False, seed=seed, **options)
    wall = time.perf_counter() - t0
    d = convergence(to_inference_data(res, posterior, np.random.default_rng(seed)), res)
    info = res.info
    return wall, d["ess_min"], d["rhat_max"], (f"{info['steps']} draws x {info['chains']} chains, "
                                               f"{info['leapfrog_per_draw']:.1f} leapfrog/draw, {info['divergences']} divergent"), info["capped"]


def compare(label, posterior, seeds, engines, nuts_options=None):
    print(f"\n{label}: {posterior.likelihood.n_obs} numbers, {posterior.ndim} parameters ({', '.join(posterior.names)})")
    invert(posterior, seed=99, max_steps=200, progress=False)  # warm-up: compile the likelihood, import ArviZ
    if "nuts" in engines or "nuts-declared" in engines:
        t0 = time.perf_counter()
        sample_nuts(posterior, np.random.default_rng(99), warmup=50, draws=50, max_draws=50, progress=False)
        print(f"  NUTS first call (tracing + compilation, 50+50 draws): {time.perf_counter() - t0:.1f} s")
    rows = {}
    candidates = {"declared": ("emcee, declared parameters", lambda s: run_emcee(posterior, s, DeclaredSpace(posterior.priors))),
                  "emcee": ("emcee, logit-CDF space", lambda s: run_emcee(posterior, s, None)),
                  "nuts": ("NUTS, logit-CDF space", lambda s: run_nuts(posterior, s, **(nuts_options or {}))),
                  "nuts-declared": ("NUTS, declared parameters", lambda s: run_nuts(
                      posterior, s, space=SamplingSpace(posterior.priors, declared=posterior.names), **(nuts_options or {})))}
    for engine, fn in (candidates[e] for e in engines):
        walls, rates = [], []
        for seed in range(seeds):
            wall, ess, rhat, what, capped = fn(seed)
            walls.append(wall)
            rates.append(ess / wall)
            print(f"  {engine:28s} seed {seed}: {wall:6.1f} s, {what}, R-hat {rhat:.4f}, ESS {ess:.0f}"
                  f"{', CAPPED' if capped else ''}")
        rows[engine] = (statistics.median(walls), statistics.median(rates))
    base = rows.get("emcee, declared parameters", next(iter(rows.values())))
    for engine, (wall, rate) in rows.items():
        print(f"  -> {engine:28s} median {wall:6.1f} s, ESS/s {rate:7.0f} ({base[0] / wall:4.1f}x faster than the baseline)")
    return rows


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--engines", nargs="+", choices=["declared", "emcee", "nuts", "nuts-declared"],
                        default=["declared", "emcee", "nuts"],
                        help="declared: emcee in the declared parameters (the baseline); emcee: in the logit space")
    parser.add_argument("--sets", nargs="+", choices=["dop", "bundled", "ptfe"], default=["dop", "bundled"],
                        help="ptfe: the PTFE full-Mueller set (minutes per engine)")
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.2f} (2 cores)")
    if "dop" in args.sets:
        compare("84-point synthetic DOP set (noise 0.005)", dop_set(), args.seeds, args.engines)
    if "bundled" in args.sets:
        compare("bundled 84-point set data/synthetic/hidden_effect.csv (DOP + BRDF), model paper", bundled_set(), args.seeds,
                args.engines)
    if "ptfe" in args.sets:
        # NUTS there: a short fixed run (its trees hit the depth cap; to convergence it ran > 10 min), to measure
        # the cost per draw and the leapfrog steps, not a converged posterior
        compare("PTFE 0.633 um, full Mueller + BRDF, paper+polarized_diffuse", ptfe_set(), args.seeds, args.engines,
                nuts_options={"warmup": 200, "draws": 100, "max_draws": 100})

    posterior = dop_set()
    data, model = posterior.likelihood.data, posterior.likelihood.model
    objective = PaperObjective(data, model, PriorSet(model.parameters))
    ga = [optimize("ga", objective, np.random.default_rng(seed), model.name) for seed in range(args.seeds)]
    truth_obj = float(objective(np.array([[TRUTH[n] for n in objective.names]]))[0])
    print(f"\npaper's GA on the DOP set: median {statistics.median(r.seconds for r in ga):.2f} s wall, "
          f"{statistics.median(r.n_evaluations for r in ga):.0f} evaluations, eq-25 objective median "
          f"{statistics.median(r.objective for r in ga):.5f} (the truth scores {truth_obj:.5f}); a point, no uncertainty")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
