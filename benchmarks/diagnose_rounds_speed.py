"""How long `diagnose --rounds 4` takes on a real full-Mueller set of about 280 geometries (issue 24, item 6).

Targets: <= 300 s at one wavelength, <= 600 s at two (median of 3, on this machine).

    python benchmarks/diagnose_rounds_speed.py [--repeats 3] [--wavelengths 0.633 0.633,1.064] [--rounds 4] [--progress]
                                               [--workers 2]

The set: NIST's PTFE (data/ptfe), every k-th geometry plus every row of a reciprocal pair (so the set measures its
own noise), at 0.633 um and at 0.633 + 1.064 um: 15 normalised Mueller elements and the BRDF per geometry. From
the paper's model, every registered effect a candidate. Each repeat runs in a fresh process with an empty JAX
cache folder, so every compilation is paid as a user's first run pays it (``--warm`` keeps one cache folder for
all repeats: a second run of the same command). Prints per repeat the wall time, the split of round 1 into base
fit, screening and confirmation, the programs XLA compiled and their seconds, the path; then the median and the machine's load average before and after.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

TARGETS_S = {1: 300.0, 2: 600.0}


def child(wavelengths: list[float], rounds: int, seed: int, size: int, progress: bool = False, workers: int = 1) -> None:
    from spacepol import configure_process

    configure_process(small_calls=True)  # as the command line runs
    import jax.monitoring

    compiled = {"count": 0, "seconds": 0.0}

    def on_event(event: str, seconds: float, **_) -> None:
        if event == "/jax/core/compile/backend_compile_duration":  # XLA's compilation of one program
            compiled["count"] += 1
            compiled["seconds"] += seconds

    jax.monitoring.register_event_duration_secs_listener(on_event)
    from spacepol.criticism.rounds import diagnose_rounds
    from spacepol.infer.measured_noise import reciprocal_pairs
    from spacepol.io import read_measurements
    from spacepol.paths import bundled
    from spacepol.physics import Model

    ptfe = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv"))
    first = ptfe.at_wavelength(wavelengths[0])
    rows = np.union1d(np.arange(0, len(first), max(1, len(first) // size)), reciprocal_pairs(first).ravel())
    keys = {(a, b, c) for a, b, c in zip(first.theta_i[rows], first.theta_r[rows], first.dphi[rows])}
    data = ptfe.at_wavelengths(wavelengths)
    data = data.select(np.array([(a, b, c) in keys for a, b, c in zip(data.theta_i, data.theta_r, data.dphi)]))
    model = Model.from_string("paper")
    if len(wavelengths) > 1:
        from spacepol.physics.spectral import SpectralModel

        model = SpectralModel(model, np.unique(data.wavelength_um))
    start = time.perf_counter()
    out = diagnose_rounds(data, model, np.random.default_rng(seed), rounds, seed=seed, progress=progress, workers=workers)
    wall = time.perf_counter() - start
    print(json.dumps({"wall": wall, "rows": len(data), "numbers": 16 * len(data), "seconds": out["seconds"],
                      "path": [r["change"] or r["model"] for r in out["rounds"]], "final": out["final_model"], "compiled": compiled,
                      "noise": {k: v["ratio"] for k, v in out["rounds"][-1]["noise"].items()}}))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--rounds", type=int, default=4)
    ap.add_argument("--size", type=int, default=260, help="every k-th geometry so that about this many remain")
    ap.add_argument("--wavelengths", nargs="+", default=["0.633", "0.633,1.064"])
    ap.add_argument("--warm", action="store_true", help="one JAX cache folder for all repeats")
    ap.add_argument("--progress", action="store_true", help="each repeat's progress lines on stderr (where the time goes)")
    ap.add_argument("--workers", type=int, default=1, help="candidates fitted at once (diagnose --workers)")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        wavelengths, seed = args.child.split(":")
        child([float(w) for w in wavelengths.split(",")], args.rounds, int(seed), args.size, args.progress, args.workers)
        return
    load = os.getloadavg()
    with tempfile.TemporaryDirectory() as scratch:
        for spec in args.wavelengths:
            walls = []
            for seed in range(args.repeats):
                cache = os.path.join(scratch, "cache" if args.warm else f"cache-{spec}-{seed}")
                env = {**os.environ, "SPACEPOL_CACHE_DIR": cache}
                done = subprocess.run([sys.executable, __file__, "--child", f"{spec}:{seed}", "--rounds", str(args.rounds),
                                       "--size", str(args.size), "--workers", str(args.workers)] + ["--progress"] * args.progress, env=env,
                                      stdout=subprocess.PIPE, stderr=None if args.progress else subprocess.PIPE, text=True)
                if done.returncode:
                    sys.exit(f"repeat {seed} at {spec} um failed:\n{(done.stderr or '')[-3000:]}")
                row = json.loads(done.stdout.strip().splitlines()[-1])
                walls.append(row["wall"])
                s = row["seconds"]
                print(f"{spec} um, seed {seed}: {row['wall']:6.1f} s for {args.rounds} rounds on {row['rows']} rows "
                      f"({row['numbers']} numbers); round 1: base fit {s['base_fit']:.0f} s, screening {s['screening']:.0f} s "
                      f"({s['candidates_screened']} candidates), confirmation {s['confirmation']:.0f} s "
                      f"({s['candidates_refitted']} refits); XLA compiled {row['compiled']['count']} programs in "
                      f"{row['compiled']['seconds']:.0f} s; path {' -> '.join(row['path'])}; "
                      f"misfit ratios {', '.join(f'{k} {v:.2f}' for k, v in row['noise'].items())}", flush=True)
            n = len(spec.split(","))
            median = float(np.median(walls))
            print(f"{spec} um: median {median:.1f} s (range {min(walls):.1f}-{max(walls):.1f}) over {len(walls)} repeats, "
                  f"{'warm' if args.warm else 'cold'} JAX cache; target {TARGETS_S[n]:.0f} s: ratio {median / TARGETS_S[n]:.2f}",
                  flush=True)
    print(f"load average before/after {load[0]:.2f}/{os.getloadavg()[0]:.2f} on {os.cpu_count()} cores, {args.workers} worker(s)")


if __name__ == "__main__":
    main()
