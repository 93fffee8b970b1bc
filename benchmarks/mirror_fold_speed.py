"""What folding mirror pairs saves (``physics.mirror``): NIST's PTFE Mueller BRDF, whose rows are measured at dphi and
-dphi: one log posterior call per parameter set, with and without the fold, interleaved in one process, by the
pointwise program summed (a large likelihood's first 20,000 sets) and by the fused one (after them).

    python benchmarks/mirror_fold_speed.py [--wavelength-um all|0.633] [--model SPEC] [--sets 32] [--rounds 5]
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

import numpy as np

from spacepol.infer import likelihood_blocks
from spacepol.infer.posterior import Posterior
from spacepol.io import read_measurements
from spacepol.paths import bundled
from spacepol.physics import Model, mirror
from spacepol.physics.spectral import SpectralModel

MODEL = "specular+smith+subsurface+phase_matrix"


def per_set_ms(call, sets: int, seconds: float = 3.0) -> float:
    """Milliseconds per parameter set of ``call`` (one batch of ``sets``), repeated for ``seconds`` after a warm-up."""
    call()
    start, n = time.perf_counter(), 0
    while time.perf_counter() - start < seconds:
        call()
        n += 1
    return (time.perf_counter() - start) / n / sets * 1e3


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--wavelength-um", default="all")
    parser.add_argument("--model", default=MODEL)
    parser.add_argument("--sets", type=int, default=32)
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args(argv)
    data = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv"))
    model = Model.from_string(args.model)
    if args.wavelength_um == "all":
        model = SpectralModel(model, np.unique(data.wavelength_um))
    else:
        data = data.at_wavelength(float(args.wavelength_um))
    print(f"PTFE at {args.wavelength_um} um, {len(data)} rows, model {args.model}; {args.sets} sets per call; "
          f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.2f}")
    posteriors, theta = {}, None
    for fold in (False, True):
        mirror.MIN_SAVED = 0.1 if fold else 1.1  # a fold that must save more than every row never happens
        posteriors[fold] = Posterior.build(data, model)
        theta = posteriors[fold].priors.rescale(np.random.default_rng(0).random((args.sets, posteriors[fold].ndim)))
        posteriors[fold].log_prob(theta)  # the program is built at the first call
        folds = posteriors[fold].likelihood._program.folds
        print(f"  fold {fold}: geometries evaluated per wavelength {[None if f is None else f.geometry.size for f in folds]}")
    mirror.MIN_SAVED = 0.1
    for label, sets_seen in (("pointwise program, summed", 0), ("fused program", likelihood_blocks.SETS_PAYING_THE_SUM)):
        times = {False: [], True: []}
        for fold in (False, True):
            posteriors[fold].likelihood._sets_in_total_calls = sets_seen
        for _ in range(args.rounds):
            for fold in (False, True):
                times[fold].append(per_set_ms(lambda fold=fold: posteriors[fold].log_prob(theta), args.sets))
        whole, folded = statistics.median(times[False]), statistics.median(times[True])
        print(f"  log posterior by the {label}, ms per set (median of {args.rounds} interleaved rounds): every row "
              f"{whole:.3f}, folded {folded:.3f}: {whole / folded:.2f}x; load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
