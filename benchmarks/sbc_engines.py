"""Simulation-based calibration of every sampling engine (issue 25, item 5).

    python benchmarks/sbc_engines.py [--replicates 100] [--control-replicates 30] [--engines emcee laplace nested nuts]
                                     [--out reports/sbc]

The problem: `specular+smith` with n ~ U(1.2, 2.0) and sigma ~ U(0.1, 0.4) (k = 0, ks = 1 fixed), 12 in-plane
geometries (theta_i 25 and 55 deg, theta_r 5-75 deg), DOP with absolute noise 0.02 and BRDF with relative noise 0.1
(Gaussian, not clipped, so the likelihood is exact). Per engine: ``--replicates`` truths from the prior, each with
its own data set and run (``spacepol.infer.calibration.calibrate``); then the negative control, the same with the
likelihood told the noise is 3x smaller than it is (a posterior 3x too narrow), which must fail. Prints per engine
the coverage of the 50 % and 90 % intervals per parameter, the chi-square p of the rank histograms, refusals, time,
and writes the rank histograms (``sbc_ENGINE.png``) and ``sbc.json`` to ``--out`` (records of engines not run this
time are kept).
"""

import argparse
import json
import os
import pathlib
import time

import numpy as np

# each engine's settings for a two-parameter problem: enough draws for 99 thinned ranks, no more
ENGINE_OPTIONS = {
    "emcee": {"max_steps": 3000},
    "laplace": {},
    "nested": {"live": 100, "replicates": 1, "effective_draws": 500},
    "nuts": {"chains": 2, "warmup": 200, "draws": 250, "max_draws": 250},
}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--replicates", type=int, default=100)
    ap.add_argument("--control-replicates", type=int, default=30)
    ap.add_argument("--engines", nargs="+", default=list(ENGINE_OPTIONS))
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--out", default="reports/sbc")
    args = ap.parse_args()

    from spacepol import configure_process

    configure_process(small_calls=True)
    from spacepol.infer.calibration import calibrate
    from spacepol.physics import Model
    from spacepol.physics.geometry import Geometry
    from spacepol.priors import Fixed, Uniform

    model = Model.from_string("specular+smith")
    theta_i = np.repeat([25.0, 55.0], 6)
    theta_r = np.tile(np.linspace(5, 75, 6), 2)
    geometry = Geometry(theta_i, theta_r, np.full(theta_i.size, 180.0))
    priors = {"n": Uniform(1.2, 2.0), "sigma": Uniform(0.1, 0.4), "k": Fixed(0.0), "ks": Fixed(1.0)}
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    load = os.getloadavg()
    print(f"load average before: {load[0]:.2f}", flush=True)
    # earlier runs' engines are kept: a run of one engine adds to (or replaces) its own records only
    results = json.loads((out / "sbc.json").read_text()) if (out / "sbc.json").is_file() else {}
    for engine in args.engines:
        options = ENGINE_OPTIONS.get(engine, {})
        for label, scale, count in (("calibration", 1.0, args.replicates), ("control", 1 / 3, args.control_replicates)):
            if count <= 0:
                continue
            start = time.perf_counter()
            c = calibrate(engine, model, priors, geometry, count, np.random.default_rng(args.seed), engine_options=options,
                          noise_dop=0.02, noise_brdf=0.1, likelihood_noise_scale=scale)
            record = c.to_json()
            results[f"{engine} {label}"] = record
            p = record["parameters"]
            print(f"{engine:8s} {label:11s} {c.replicates:4d} replicates ({c.refused} refused) "
                  f"{time.perf_counter() - start:6.0f} s | "
                  + " | ".join(f"{n}: 50 % {v['coverage_50']:.2f}, 90 % {v['coverage_90']:.2f}, rank p {v['rank_p_value']:.3f}"
                               for n, v in p.items())
                  + f" | {'calibrated' if c.calibrated else 'NOT calibrated'}", flush=True)
            c.figure().savefig(out / f"sbc_{engine}{'' if scale == 1 else '_control'}.png", dpi=110)
            (out / "sbc.json").write_text(json.dumps(results, indent=1))
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
