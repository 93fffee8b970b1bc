"""``invert-mcmc demo``: the chain on bundled data, report in one folder.

1. Forward model on the geometry of NIST's measured PTFE Mueller BRDF (0.633 um, plane of
   incidence): ``ptfe_forward.csv``, ``ptfe_dop.png``.
2. Bayesian inversion of that measurement (DOP and BRDF) with the paper's model, compared with
   PTFE's known bulk index (about 1.35): ``ptfe_paper/`` (summary.json, posterior.nc, corner,
   fit and residual plots, report.html).
3. ``report.html`` links them and says what was found.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..infer.inversion import invert
from ..infer.posterior import Posterior
from ..io import read_measurements, write_table
from ..paths import bundled
from ..physics.geometry import Geometry
from ..physics.model import Model
from . import html as H
from .figures import dop_versus_theta_r
from .run_report import write_run_report

# Sintered PTFE: bulk index ~1.35, non-absorbing, very rough, mostly volume scattering.
PTFE_GUESS = {"n": 1.35, "k": 0.0, "sigma": 0.35, "ks": 0.08, "rho_d": 1.0}
PTFE_INDEX = 1.35


def _fine_grid(theta_i_values):
    theta_r = np.linspace(0.0, 85.0, 86)
    ti = np.repeat(theta_i_values, 2 * theta_r.size)
    tr = np.tile(np.concatenate([theta_r, theta_r]), len(theta_i_values))
    dphi = np.tile(np.concatenate([np.full(theta_r.size, 180.0), np.zeros(theta_r.size)]), len(theta_i_values))
    return Geometry(ti, tr, dphi)


def forward_comparison(data, out: Path) -> list[str]:
    models = {name: Model.from_string(name) for name in ("paper", "paper+polarized_diffuse")}
    params = {"paper": PTFE_GUESS, "paper+polarized_diffuse": {**PTFE_GUESS, "rho_d": 0.5, "rho_pd": 0.5}}
    columns = {"theta_i": data.theta_i, "theta_r": data.theta_r, "dphi": data.dphi,
               "dop_measured": data.dop, "brdf_measured": data.brdf}
    curves, lines = {}, []
    shown = [0.001, 30.0, 60.0, 75.0]
    fine = _fine_grid(shown)
    for name, model in models.items():
        prediction = model.evaluate(params[name], data.geometry)
        columns[f"dop_{name}"] = prediction.dop
        columns[f"brdf_{name}"] = prediction.brdf
        curves[name] = (fine, model.evaluate(params[name], fine).dop)
        rmse = np.sqrt(np.mean((prediction.dop - data.dop) ** 2))
        lines.append(f"{name}: RMSE(DOP) {rmse:.4f} with hand-set PTFE-like parameters (not fitted)")
    write_table(out / "ptfe_forward.csv", columns, {"source": "NIST PTFE Mueller BRDF (Germer 2017)", "wavelength_um": 0.633})
    subset = data.select(np.isin(np.round(data.theta_i), np.round(shown)))
    fig = dop_versus_theta_r(subset, curves, title="PTFE, 0.633 um, plane of incidence: data vs forward model")
    fig.savefig(out / "ptfe_dop.png", dpi=120)
    return lines


def run_demo(out: Path, seed: int = 0) -> None:
    out.mkdir(parents=True, exist_ok=True)
    source = bundled("ptfe", "ptfe_mueller_brdf.csv")
    data = read_measurements(source).at_wavelength(0.633).in_plane()
    print(f"1/2 forward model on {len(data)} PTFE geometries (0.633 um, plane of incidence)")
    forward_lines = forward_comparison(data, out)
    for line in forward_lines:
        print("   " + line)

    print("2/2 inversion of the PTFE measurement (DOP + BRDF) with the paper's model")
    posterior = Posterior.build(data, Model.from_string("paper"))
    inv = invert(posterior, seed=seed, backend_path=None, progress=True)
    summary = write_run_report(inv, out / "ptfe_paper", f"{source} (0.633 um, in-plane)", references={"n": PTFE_INDEX})
    n = summary["parameters"]["n"]
    d = summary["diagnostics"]
    print(f"   n = {n['median']:.3f} [90 %: {n['q05']:.3f}, {n['q95']:.3f}] against PTFE's bulk index {PTFE_INDEX}; "
          f"R-hat max {d['rhat_max']:.4f}, ESS min {d['ess_min']:.0f}")

    sections = [
        ("What this is", H.paragraph(
            "spacepol's demo on NIST's measured Mueller-matrix BRDF of sintered PTFE (Germer, Appl. Opt. 56, 2017), "
            "0.633 um, plane of incidence: the forward model, then a Bayesian inversion of DOP and BRDF.")),
        ("1. Forward model", H.bullets(forward_lines) + H.image(H.png_file_to_data_uri(out / "ptfe_dop.png"))),
        ("2. Inversion with the paper's model", H.bullets(
            [f"n = {n['median']:.3f}, 90 % interval [{n['q05']:.3f}, {n['q95']:.3f}]; R-hat max {d['rhat_max']:.4f}, "
             f"ESS min {d['ess_min']:.0f}; reduced chi^2 {summary['fit']['chi2_red']:.2f} with inferred noise "
             f"(DOP {summary['parameters']['sigma_dop']['median']:.4f}, BRDF {100 * summary['parameters']['sigma_brdf_rel']['median']:.0f} %)."]
            + [summary["references"]["n"]["explanation"]] + summary["residual_structure"]["findings"]
            + summary["identifiability"]["findings"])
         + '<p><a href="ptfe_paper/report.html">Full report of the inversion</a></p>'
         + H.image(H.png_file_to_data_uri(out / "ptfe_paper" / "residuals.png"),
                   "Residuals: the BRDF's U shape is the paper's cos(theta_r) body term failing a nearly Lambertian "
                   "material; DOP residuals lean positive where DOP is small (noise bias of a measured DOP).")),
    ]
    (out / "report.html").write_text(H.page("spacepol demo: PTFE", sections), encoding="utf-8")
    print(f"wrote {out}/report.html (and ptfe_forward.csv, ptfe_dop.png, ptfe_paper/)")
