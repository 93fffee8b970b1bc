"""The four-wavelength PTFE inversion with the study's final model, phase by phase (issue 47, item 7; goal <= 10 min
on 2 cores): the study's own fit (``studies/ptfe_models.py``'s ``fit``: the search on every 8th row polished on all,
then diagnose's posterior, Laplace-IS with its walkers' width check, or emcee where the check refuses), every row,
the noise as the measurement shows it (``--noise-profile``), with the command line's process settings.

    python benchmarks/ptfe_final_model_speed.py [--search-every 8] [--seed 0]

Compiled programs are kept on disk as the command line keeps them (``SPACEPOL_CACHE_DIR``, else the user's cache
folder): the first run on a machine compiles everything (cold), later ones read what they can (warm). The script
says which it was: run it with ``SPACEPOL_CACHE_DIR`` set to a new folder for a cold figure.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "studies"))

FINAL = ("specular+smith+subsurface+phase_matrix [w_pm=1 dl_pm=0 fc_pm=0 pm_m44_0=1 pm_m44_180=1 k@0.351=0 "
         "k@0.532=0 k@0.633=0 k@1.064=0 ks=1]")
GOAL_S = 600.0


def timed(module, name: str, phases: dict, label: str) -> None:
    """Replace ``module.name`` by a wrapper adding its wall time to ``phases[label]``."""
    inner = getattr(module, name)

    def wrapper(*args, **kwargs):
        start = time.perf_counter()
        try:
            return inner(*args, **kwargs)
        finally:
            phases[label] = phases.get(label, 0.0) + time.perf_counter() - start

    setattr(module, name, wrapper)


def cpu_name() -> str:
    try:
        return next(line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines()
                    if line.startswith("model name"))
    except (OSError, StopIteration):
        return platform.processor() or platform.machine()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--search-every", type=int, default=8)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    from spacepol._runtime import compilation_cache_folder

    folder = Path(compilation_cache_folder() or os.devnull)  # "": the cache turned off, nothing held
    held = len(list(folder.glob("*"))) if folder.is_dir() else 0  # before anything is compiled
    from spacepol import configure_process

    configure_process(small_calls=True)
    import ptfe_models as study

    from spacepol.infer.engines import laplace_is

    print(f"{cpu_name()}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.2f}; compiled programs in {folder}: "
          f"{held} files at the start ({'cold' if held == 0 else 'warm'})", flush=True)
    phases: dict[str, float] = {}
    timed(study, "find_optimum_on_every", phases, "search (every 8th row, polished on all)")
    timed(laplace_is, "laplace_importance", phases, "mode, Hessian, importance draws")
    timed(laplace_is, "spread_check", phases, "walkers' width check")
    timed(laplace_is, "to_inference_data", phases, "InferenceData")
    timed(laplace_is, "importance_loo", phases, "PSIS-LOO (its pointwise values apart)")
    timed(study, "invert", phases, "emcee (where the check refused)")
    start = time.perf_counter()
    data = study.load("all")
    noise = study.measured_noise(data)
    scatter = study.exit_scatter(data)
    data.mueller_noise_profile = study.measured_noise_profile(data, noise)
    prepared = time.perf_counter() - start
    record, inv, _ = study.fit(data, FINAL, args.seed, "laplace", 4000, noise, scatter, args.search_every)
    total = time.perf_counter() - start
    print(f"\n{len(data)} geometries x 16 numbers, {record['free_parameters']} free parameters; engine "
          f"{record['engine']}, Pareto k {record['pareto_k']}, widest SD growth {record['sd_growth_max']}"
          + (f"; Laplace refused: {record['laplace_refused']}" if record["laplace_refused"] else ""))
    check = inv.summary.sampler.get("spread_check", {})
    if check.get("walkers_run"):
        print(f"walkers: {check['walkers']} x {check['steps']} steps; effective importance draws "
              f"{inv.summary.diagnostics['ess_min']:.0f} of {inv.summary.sampler['draws']}")
    print(f"\n| phase | s |\n|---|---|\n| data and measured noise | {prepared:.1f} |")
    for label, seconds in phases.items():
        print(f"| {label} | {seconds:.1f} |")
    rest = total - prepared - sum(phases.values())
    print(f"| the rest (pointwise values for LOO, summary, residuals) | {rest:.1f} |\n| **total** | **{total:.1f}** |")
    print(f"\ngoal {GOAL_S:.0f} s: {'met' if total <= GOAL_S else 'not met'} ({total / GOAL_S:.2f}x); "
          f"ELPD-LOO {record['elpd_loo']:.1f} +- {record['elpd_loo_se']:.1f}; load at the end {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
