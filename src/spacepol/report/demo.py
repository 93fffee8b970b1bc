"""``invert-mcmc demo``: the chain on bundled data.

At this stage of the toolkit the demo runs the forward model on the geometry of NIST's
measured PTFE Mueller BRDF (0.633 um, plane of incidence) and writes the comparison as a CSV
and a figure.  Later stages (inversion, criticism, contrast) extend it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..io import read_measurements, write_table
from ..paths import bundled
from ..physics.geometry import Geometry
from ..physics.model import Model
from .figures import dop_versus_theta_r

# Sintered PTFE: bulk index ~1.35, non-absorbing, very rough, mostly volume scattering.
PTFE_GUESS = {"n": 1.35, "k": 0.0, "sigma": 0.35, "ks": 0.08, "rho_d": 1.0}


def _fine_grid(theta_i_values):
    theta_r = np.linspace(0.0, 85.0, 86)
    ti = np.repeat(theta_i_values, 2 * theta_r.size)
    tr = np.tile(np.concatenate([theta_r, theta_r]), len(theta_i_values))
    dphi = np.tile(np.concatenate([np.full(theta_r.size, 180.0), np.zeros(theta_r.size)]), len(theta_i_values))
    return Geometry(ti, tr, dphi)


def run_demo(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    data = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv")).at_wavelength(0.633).in_plane()
    models = {name: Model.from_string(name) for name in ("paper", "paper+polarized_diffuse")}
    params = {"paper": PTFE_GUESS, "paper+polarized_diffuse": {**PTFE_GUESS, "rho_d": 0.5, "rho_pd": 0.5}}

    columns = {"theta_i": data.theta_i, "theta_r": data.theta_r, "dphi": data.dphi,
               "dop_measured": data.dop, "brdf_measured": data.brdf}
    curves = {}
    shown = [0.001, 30.0, 60.0, 75.0]
    fine = _fine_grid(shown)
    for name, model in models.items():
        prediction = model.evaluate(params[name], data.geometry)
        columns[f"dop_{name}"] = prediction.dop
        columns[f"brdf_{name}"] = prediction.brdf
        curves[name] = (fine, model.evaluate(params[name], fine).dop)
        rmse = np.sqrt(np.mean((prediction.dop - data.dop) ** 2))
        print(f"  {name:<28s} RMSE(DOP) vs PTFE at 0.633 um = {rmse:.4f} (hand-set parameters, not fitted)")
    write_table(out / "ptfe_forward.csv", columns, {"source": "NIST PTFE Mueller BRDF (Germer 2017)", "wavelength_um": 0.633})

    subset = data.select(np.isin(np.round(data.theta_i), np.round(shown)))
    fig = dop_versus_theta_r(subset, curves, title="PTFE, 0.633 um, plane of incidence: data vs forward model")
    fig.savefig(out / "ptfe_dop.png", dpi=120)
    print(f"wrote {out / 'ptfe_forward.csv'} and {out / 'ptfe_dop.png'}")
