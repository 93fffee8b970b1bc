"""What one criticism loop costs, as a ratio: `diagnose --rounds 4` from `paper` against one converged `run` of
`paper` on the same data, in one process.

Goal: both ratios <= 4, and the PTFE diagnosis <= 120 s on 2 cores.

    python benchmarks/diagnose_cost_ratio.py [--sets ptfe,hidden] [--rounds 4] [--seed 0] [--profile]

``--profile``: the diagnosis under cProfile, its time split by phase (the cumulative time of the functions that do
each: ``PHASES``; they nest, so the phases overlap where one calls another, e.g. compilation inside screening).

The sets: (a) NIST's PTFE at 0.633 um, the plane of incidence, full Mueller matrix and BRDF; (b) the bundled 84-point
DOP + BRDF set with a hidden effect. For each: the wall time of `invert` (emcee to convergence, the default of
`invert-mcmc run`) and of `diagnose --rounds` (the default posterior, Laplace-IS where trusted), the split of the
first round into base fit, screening and confirmation, the path, the ratio, a table of every round's and the slot
pass's base fit, screening, leaders' multistarts and refits (from the record's ``seconds_rounds`` and
``seconds_slot_pass``); the machine, its cores and the load average before and after. The run goes first, so that
it pays the compilations it shares with diagnose.
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import platform
import time

import numpy as np

import spacepol
from spacepol.paths import bundled


# phase: (module path suffix, function name) whose cumulative time is the phase's
PHASES = {
    "compilation (JAX tracing and XLA)": [("jax/_src/pjit.py", "cache_miss")],
    "screening (each change near the base's optimum)": [("criticism/candidate_fits.py", "_screen")],
    "leaders' global multistart": [("criticism/candidate_fits.py", "_leader")],
    "refits (posteriors for ELPD-LOO)": [("criticism/candidate_fits.py", "fit_for_elpd")],
    "PSIS-LOO": [("infer/diagnostics.py", "loo"), ("infer/laplace.py", "importance_loo")],
    "likelihood calls (all phases)": [("infer/likelihood.py", "_call")],
}


def phase_table(profile: cProfile.Profile) -> list[tuple[str, float]]:
    """(phase, cumulative s) of ``PHASES`` in ``profile``; a phase's functions are summed (they do not nest)."""
    stats = pstats.Stats(profile).stats  # {(file, line, name): (cc, nc, tt, ct, callers)}
    out = []
    for phase, functions in PHASES.items():
        total = sum(ct for (file, _, name), (_, _, _, ct, _) in stats.items()
                    if any(file.endswith(suffix) and name == fn for suffix, fn in functions))
        out.append((phase, total))
    return out


def round_table(content: dict, total_s: float) -> list[str]:
    """Where the diagnosis's time went, from its own record (no profiler): per round and for the last pass over the
    slot alternatives, the base fit, the screening, the leaders' global multistarts and the refits (their posteriors and
    PSIS-LOO); the rest (building the record and the rungs) as the remainder of ``total_s``."""
    passes = [(f"round {i + 1}", s) for i, s in enumerate(content.get("seconds_rounds", []))]
    if content.get("seconds_slot_pass"):
        passes.append(("slot pass", content["seconds_slot_pass"]))
    if not passes:
        return []
    lines = [f"  {'':<10s} {'base fit':>9s} {'screening':>10s} {'leaders':>8s} {'refits':>8s} {'refitted':>8s}"]
    sums = np.zeros(4)
    for name, s in passes:
        row = np.array([s["base_fit"], s["screening"], s["leader_search"], s["confirmation"] - s["leader_search"]])
        sums += row
        lines.append(f"  {name:<10s} " + " ".join(f"{v:{w}.1f}" for v, w in zip(row, (9, 10, 8, 8)))
                     + f" {s['candidates_refitted']:8d}")
    lines.append(f"  {'all':<10s} " + " ".join(f"{v:{w}.1f}" for v, w in zip(sums, (9, 10, 8, 8)))
                 + f"; the rest {total_s - sums.sum():.1f} s of {total_s:.1f} s")
    return lines


def sets() -> dict:
    """The two data sets by name."""
    return {"ptfe": lambda: spacepol.load(bundled("ptfe", "ptfe_mueller_brdf.csv"), wavelength_um=0.633, in_plane=True),
            "hidden": lambda: spacepol.load(bundled("synthetic", "hidden_effect.csv"))}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sets", default="ptfe,hidden")
    ap.add_argument("--rounds", type=int, default=4)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--profile", action="store_true", help="split the diagnosis's time by phase (cProfile)")
    args = ap.parse_args()
    spacepol.configure_process(small_calls=True)  # as the command line runs
    load = os.getloadavg()
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, load {load[0]:.2f}", flush=True)
    for name in args.sets.split(","):
        data = sets()[name]()
        start = time.perf_counter()
        run = spacepol.invert(data, "paper", seed=args.seed, progress=False)
        run_s = time.perf_counter() - start
        profile = cProfile.Profile() if args.profile else None
        start = time.perf_counter()
        if profile:
            profile.enable()
        found = spacepol.diagnose(data, "paper", rounds=args.rounds, seed=args.seed)
        if profile:
            profile.disable()
        diagnose_s = time.perf_counter() - start
        first = found.content.get("seconds") or found.content["rounds"][0].get("seconds", {})
        path = " -> ".join(r["change"] or r["model"] for r in found.content.get("rounds", []))
        print(f"{name}: {len(data)} geometries; run {run_s:.1f} s (R-hat {run.diagnostics.rhat_max:.3f}); diagnose "
              f"--rounds {args.rounds} {diagnose_s:.1f} s (round 1: base fit {first.get('base_fit', np.nan):.0f} s, "
              f"screening {first.get('screening', np.nan):.0f} s, confirmation {first.get('confirmation', np.nan):.0f} s); "
              f"path {path}; ratio {diagnose_s / run_s:.2f} (goal <= 4)", flush=True)
        for line in round_table(found.content, diagnose_s):
            print(line)
        if profile:
            for phase, seconds in phase_table(profile):
                print(f"  {phase:<50s} {seconds:8.1f} s ({100 * seconds / diagnose_s:4.0f} %)")
    print(f"load average before/after {load[0]:.2f}/{os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
