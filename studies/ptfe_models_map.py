"""NIST's PTFE under several models at their posterior maximum: the log posterior, the inferred noise per
element group against the noise the data's reciprocal pairs measure, and the index-like parameters.

A quick comparison before the full posteriors: the maximum is found by ``find_optimum_profiled`` (searches with
the noise levels profiled out, then the full posterior polished). Without reciprocal pairs in the rows chosen
(the plane of incidence alone has none) the measured noise column stays empty.

    python studies/ptfe_models_map.py [--wavelength-um 0.633] [--in-plane] [--seed 0]
                                      [--models paper,specular+smith+subsurface+volume,specular+smith+subsurface+phase_matrix]
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

from spacepol.infer.optimum import find_optimum_profiled
from spacepol.infer.posterior import Posterior
from spacepol.io import read_measurements
from spacepol.paths import bundled
from spacepol.physics import Model
from spacepol.physics.spectral import SpectralModel

MODELS = "paper,specular+smith+subsurface+volume,specular+smith+subsurface+phase_matrix"
INDEX_LIKE = ("n", "n_pm", "n_host")


def load(wavelengths: str, in_plane: bool):
    data = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv"))
    if wavelengths != "all":
        data = data.at_wavelengths([float(w) for w in wavelengths.split(",")])
    return data.in_plane() if in_plane else data


def fit(data, spec: str, seed: int) -> dict:
    """The maximum of ``spec``'s posterior on ``data``: log posterior, values, measured noise, seconds."""
    model = Model.from_string(spec)
    lams = np.unique(data.wavelength_um)
    if len(lams) > 1:
        model = SpectralModel(model, lams)
    start = time.perf_counter()
    posterior = Posterior.build(data, model)
    value, theta = find_optimum_profiled(posterior, np.random.default_rng(seed), evaluations=3000)
    return {"model": spec, "log_posterior": value, "values": dict(zip(posterior.priors.names, theta)),
            "measured": {k: m.value for k, m in posterior.measured_noise.items()}, "ndim": posterior.ndim,
            "seconds": time.perf_counter() - start}


def row(result: dict) -> str:
    values, measured = result["values"], result["measured"]
    noise = [f"{k} {v:.4f}" + (f" ({v / measured[k]:.2f}x)" if k in measured else "")
             for k, v in values.items() if k.startswith("sigma_")]
    index = [f"{k} {v:.3f}" for k, v in values.items() if k.split("@")[0] in INDEX_LIKE]
    return (f"| {result['model']} | {result['ndim']} | {result['log_posterior']:.1f} | {', '.join(noise)} | "
            f"{', '.join(index)} | {result['seconds']:.0f} |")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--wavelength-um", default="0.633")
    parser.add_argument("--in-plane", action="store_true")
    parser.add_argument("--models", default=MODELS)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    data = load(args.wavelength_um, args.in_plane)
    print(f"PTFE: {len(data)} geometries at {', '.join(f'{w:g}' for w in np.unique(data.wavelength_um))} um"
          f"{' (plane of incidence)' if args.in_plane else ''}; {os.cpu_count()} cores, load {os.getloadavg()[0]:.2f}")
    print("| model | free parameters | max log posterior | inferred noise (x measured) | indices | s |")
    print("|---|---|---|---|---|---|")
    for spec in args.models.split(","):
        print(row(fit(data, spec, args.seed)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
