"""``invert-mcmc demo``: the chain on bundled data, report in one folder.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..criticism.diagnose import diagnose
from ..criticism.changes import parse
from ..criticism import reciprocity
from ..criticism.ladder import climb
from ..errors import SpacepolError
from ..infer.identifiability import bound_finding
from ..infer.inversion import invert
from ..io.atomic import write_json, write_text
from ..infer.posterior import Posterior
from ..io import read_measurements, write_table
from ..paths import bundled
from ..physics.geometry import Geometry
from ..physics.model import Model
from . import html as H
from .figures import dop_versus_theta_r
from ..detect.scenario import default_scenario
from ..io.atomic import save_figure
from ..skylight.rayleigh import RayleighSky
from .contrast_report import make_contrast_report, table3_lines
from .diagnose_report import significance_statement, write_diagnose_report
from .sky_figures import projection_distortion_figure, sky_maps_figure
from .ladder_report import write_ladder_report
from .run_report import write_run_report
from ..infer.run_summary import RunSummary

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
    """The demo's first section: the paper's model and paper+polarized_diffuse at a PTFE-like guess against PTFE's
    measured DOP and BRDF; writes the CSV and figure, returns the lines it reports."""
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
        curves[name] = (fine, model.dop(params[name], fine))
        rmse = np.sqrt(np.mean((prediction.dop - data.dop) ** 2))
        lines.append(f"{name}: RMSE(DOP) {rmse:.4f} with hand-set PTFE-like parameters (not fitted)")
    write_table(out / "ptfe_forward.csv", columns, {"source": "NIST PTFE Mueller BRDF (Germer 2017)", "wavelength_um": 0.633})
    subset = data.select(np.isin(np.round(data.theta_i), np.round(shown)))
    fig = dop_versus_theta_r(subset, curves, title="PTFE, 0.633 um, plane of incidence: data vs forward model")
    save_figure(fig, out / "ptfe_dop.png")
    return lines


def criticise(data, base, out: Path, label: str, seed: int, max_additions: int = 2) -> tuple:
    """diagnose (reusing the base fit), then a ladder adding the verdict and the next significant,
    non-twin effects; writes ``out/diagnose/`` and ``out/ladder/``."""
    model = base.posterior.likelihood.model
    report = diagnose(data, model, np.random.default_rng(seed), seed=seed, base=base)
    base, confirmed = report.base, report.confirmed
    write_diagnose_report(report.to_json(), base, confirmed, out / "diagnose", label)
    write_json(out / "diagnose.json", report.to_json())
    additions, current = [], model
    if report["verdict"] != "none":
        twins = set(report["ranking"][0].get("tied_with", []))
        for r in report["ranking"]:
            named = r["effect"] if r["change"] == f"add {r['effect']}" else r["change"]
            if not r["significant"] or named in twins or len(additions) == max_additions:
                continue
            try:  # two significant changes may exclude each other (add lambertian, replace body by lambertian)
                current = parse(current, r["change"]).model
            except SpacepolError:
                continue
            additions.append(r["change"])
    fitted = {base.summary.model: base} | {c.inversion.summary.model: c.inversion for c in confirmed}
    rungs = climb(data, model, additions, seed=seed, fitted=fitted)
    write_ladder_report(rungs, out / "ladder")
    return report, rungs


def _criticism_section(report, rungs, folder: str) -> str:
    public = [r.to_json() for r in rungs]
    noise = list(dict.fromkeys(k for r in public for k in r.get("inferred_noise", {})))
    if noise:  # inferred noise: chi^2 ~ 1 by construction; the inferred level is the error that falls
        head = ["model", "RMSE(DOP)", "ELPD-LOO"] + [f"inferred {n}" for n in noise]
        rows = [[r["model"], "n/a" if r["rmse_dop"] is None else f"{r['rmse_dop']:.4f}",
                 f"{r['elpd_loo']:.1f} +- {r['elpd_loo_se']:.1f}"]
                + [f"{r['inferred_noise'].get(n, float('nan')):.4g}" for n in noise] for r in public]
        caption = "The ladder: residuals per rung (top); ELPD-LOO and the inferred noise per rung (bottom)."
    else:
        head = ["model", "RMSE(DOP)", "reduced chi^2", "ELPD-LOO"]
        rows = [[r["model"], "n/a" if r["rmse_dop"] is None else f"{r['rmse_dop']:.4f}", f"{r['chi2_red']:.2f}",
                 f"{r['elpd_loo']:.1f} +- {r['elpd_loo_se']:.1f}"] for r in public]
        caption = "The ladder: residuals per rung (top); ELPD-LOO and reduced chi^2 per rung (bottom)."
    flags = [f"{r['model']}: {bound_finding(f)}" for r in public for f in r.get("at_bound", [])]
    return (H.paragraph(f"verdict: {report['verdict']}. {report['conclusion']}") + H.paragraph(significance_statement(report))
            + H.table(head, rows) + (H.bullets(flags) if flags else "")
            + H.image(H.png_file_to_data_uri(Path(folder) / "ladder" / "ladder.png"), caption)
            + H.image(H.png_file_to_data_uri(Path(folder) / "diagnose" / "signatures.png"),
                      "Residuals of the base fit (dots) and each candidate's signature (crosses).")
            + f'<p><a href="{Path(folder).name}/diagnose/report.html">Full diagnosis</a></p>')


def _noise_words(summary: RunSummary) -> str:
    """'sigma_m_pol 0.0075, ..., sigma_brdf_rel 32 %': the inferred noise levels, medians."""
    words = []
    for name, q in summary.parameters.items():
        if name.startswith("sigma_"):
            words.append(f"{name} {100 * q['median']:.0f} %" if name.endswith("_rel") else f"{name} {q['median']:.4f}")
    return ", ".join(words) or "none (the file gives errors)"


def hidden_truth(metadata: dict) -> dict:
    """What synth hid: the effects beyond the paper's model and their values (from the file header)."""
    model = metadata.get("model", "")
    base = {"specular", "shadowing", "body"}
    hidden = [e for e in model.split("+") if e and e not in base]
    values = {k[6:]: v for k, v in metadata.items() if k.startswith("truth_")}
    own = {name: values[name] for e in hidden for name in _effect_parameters(e) if name in values}
    return {"hidden_effect": "+".join(hidden) or "none", "hidden_parameters": own or "(none: a change of shape)",
            "description": f"{len(hidden)} effect(s), revealed at the end"}


def _effect_parameters(name: str) -> list[str]:
    from ..physics.registry import registry

    return [p.name for p in registry.get(name).parameters]


DEMO_PASS = {"tle": ("tle", "iss_zarya_2014-01-20.tle"), "site": (43 + 8 / 60, 125 + 32 / 60, 200.0),
             "start": "2014-01-21T00:33:00Z", "end": "2014-01-21T00:40:00Z", "step_s": 20.0}


def observe_demo_pass(run_dir: Path, out: Path, seed: int) -> tuple:
    """The run's material on the bundled daytime pass (DEMO_PASS): observe/ and what it found, in sentences."""
    from ..detect.observation import observe_result
    from ..infer.result import Result
    from .observe_report import best_times, write_observe_report

    observation, assumptions = observe_result(Result.load(run_dir), bundled(*DEMO_PASS["tle"]), DEMO_PASS["site"],
                                              DEMO_PASS["start"], DEMO_PASS["end"], step_s=DEMO_PASS["step_s"], draws=100,
                                              rng=np.random.default_rng(seed))
    content = write_observe_report(observation, out, assumptions)
    over = content["over_pass"]
    best = {name: (row["p_detect"][name]["median"], row["time_utc"], row["elevation_deg"])
            for name, row in best_times(content).items()}
    lines = [f"{content['satellite']} from {DEMO_PASS['start']} to {DEMO_PASS['end']} over the paper's site, "
             f"{over['steps_above_horizon']} steps above the horizon; a 1 m cube with a 4 m^2 sun-tracking panel of this "
             f"material, the default camera (an IMX250MZR-class sensor behind the paper's 2.544 m^2 pupil), exposure {observation.camera.exposure_s:g} s."]
    lines += [f"{name}: best median P_d {p:.3f} at {t} (elevation {e:.1f} deg); P(detected at least once over the pass) "
              f"{over['p_detect'][name]['median']:.3f} [{over['p_detect'][name]['q05']:.3f}, {over['p_detect'][name]['q95']:.3f}]"
              for name, (p, t, e) in best.items()]
    lines.append(f"A target-free sky gives at least one false alarm over the pass with probability {over['p_false_alarm']:.3f}.")
    return observation, lines


def _demo_sections(out: Path, forward_lines, summary, hidden_path, hidden, truth, hidden_report, hidden_rungs, found,
                   ptfe_report, ptfe_rungs, itself, scenario, contrast, limit_line, observed) -> list:
    """The demo page's six sections, from what each step found."""
    n, d = summary.parameters["n"], summary.diagnostics
    sun = (contrast["sun"]["zenith_deg"], contrast["sun"]["azimuth_deg"])
    return [
        ("What this is", H.paragraph(
            "spacepol's demo on NIST's measured Mueller-matrix BRDF of sintered PTFE (Germer, Appl. Opt. 56, 2017), "
            "0.633 um, plane of incidence: the forward model, a Bayesian inversion of the measured Mueller matrix "
            "(15 normalised elements) and BRDF, then model criticism "
            "(what is missing from the paper's model, and the error falling as it is added), first on a synthetic set "
            "with a known hidden effect, then on PTFE.")),
        ("1. Forward model", H.bullets(forward_lines) + H.image(H.png_file_to_data_uri(out / "ptfe_dop.png"))),
        ("2. Inversion with the paper's model", H.bullets(
            [f"n = {n['median']:.3f}, 90 % interval [{n['q05']:.3f}, {n['q95']:.3f}]; R-hat max {d['rhat_max']:.4f}, "
             f"ESS min {d['ess_min']:.0f}; inferred noise: {_noise_words(summary)} (with inferred noise, reduced "
             f"chi^2 is ~1 by construction)."]
            + [summary.references["n"]["explanation"]] + summary.residual_findings
            + summary.identifiability["findings"])
         + '<p><a href="ptfe_paper/report.html">Full report of the inversion</a></p>'
         + H.image(H.png_file_to_data_uri(out / "ptfe_paper" / "residuals.png"),
                   "Residuals: the BRDF's U shape is the paper's cos(theta_r) body term failing a nearly Lambertian "
                   "material; DOP residuals lean positive where DOP is small (noise bias of a measured DOP).")),
        ("3. A hidden effect, found and closed", H.paragraph(
            f"{hidden_path.name}: {len(hidden)} synthetic geometries from the paper's model plus one hidden effect "
            f"({truth['description']}). diagnose sees only the data.")
         + _criticism_section(hidden_report, hidden_rungs, out / "hidden")
         + H.paragraph(f"Revealed: the hidden effect was {truth['hidden_effect']} with {truth['hidden_parameters']} ({found}).")),
        ("4. What the paper's model misses on PTFE", _criticism_section(ptfe_report, ptfe_rungs, out / "ptfe")
         + H.paragraph("What the measurement says about itself, without a model (all 1,824 geometries at 0.633 um; "
                       "the PTFE study, reports/ptfe_models/report.md, fits every one of them):") + H.bullets(itself)),
        ("5. Against the daytime sky: Table 3 as distributions", H.paragraph(
            f"The PTFE posterior (paper's model) at the paper's geometry (theta_i 30 deg, dphi 180 deg, theta_r 0-80 deg), "
            f"the sky of the paper's site and time (sun from astropy: zenith {sun[0]:.2f} deg, azimuth {sun[1]:.2f} deg; "
            f"the paper's 29 deg 30' / -4 deg 32' is wrong for that date), Rayleigh with P_max in "
            f"[{scenario.sky['p_max_low']:g}, {scenario.sky['p_max_high']:g}], Table 2's instrument, micro-polarizer superpixels.")
         + H.table(["case", "target DOP", "sky DOP", "limiting magnitude", "raw contrast", "polarization contrast"],
                   [[r["case"]] + [f"{r[k]['median']:.4g} [{r[k]['q05']:.4g}, {r[k]['q95']:.4g}]" for k in
                                   ("target_dop", "sky_dop", "limiting_magnitude", "intensity_contrast", "polarization_contrast")]
                    for r in contrast["rows"]])
         + H.paragraph(contrast["dominance"]) + H.paragraph(limit_line.capitalize() + ".")
         + H.image(H.png_file_to_data_uri(out / "contrast" / "sky_maps.png"), "Sky DOP and AoP in the three projections, the two target directions in red.")
         + H.image(H.png_file_to_data_uri(out / "contrast" / "projections.png"), "What each projection does to shapes and areas.")
         + '<p><a href="contrast/report.html">Full contrast report (radiometry, the paper\'s Table 3 recomputed)</a></p>'),
        ("6. A daytime pass", H.bullets(observed)
         + H.image(H.png_file_to_data_uri(out / "observe" / "light_curves.png"), "Light curves and P_d(t) per detector.")
         + '<p><a href="observe/report.html">Full pass report (assumptions, simulated exposures, every time step)</a></p>'),
    ]


def run_demo(out: Path, seed: int = 0) -> None:
    """The demo: forward model on PTFE, inversion, a hidden effect named on a synthetic set, diagnose and ladder on
    PTFE, Table 3 as distributions, the material on a daytime pass; report.html in ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    source = bundled("ptfe", "ptfe_mueller_brdf.csv")
    measured = read_measurements(source).at_wavelength(0.633)
    data = measured.in_plane()
    print(f"1/6 forward model on {len(data)} PTFE geometries (0.633 um, plane of incidence)")
    forward_lines = forward_comparison(data, out)
    for line in forward_lines:
        print("   " + line)

    print("2/6 inversion of the PTFE measurement (full Mueller matrix + BRDF) with the paper's model")
    posterior = Posterior.build(data, Model.from_string("paper"))
    inv = invert(posterior, seed=seed, backend_path=None, progress=True)
    summary = write_run_report(inv, out / "ptfe_paper", f"{source} (0.633 um, in-plane)", references={"n": PTFE_INDEX})
    n = summary.parameters["n"]
    d = summary.diagnostics
    print(f"   n = {n['median']:.3f} [90 %: {n['q05']:.3f}, {n['q95']:.3f}] against PTFE's bulk index {PTFE_INDEX}; "
          f"R-hat max {d['rhat_max']:.4f}, ESS min {d['ess_min']:.0f}")

    hidden_path = bundled("synthetic", "hidden_effect.csv")
    print(f"3/6 what is missing? fit -> diagnose -> ladder on {hidden_path.name} (a synthetic set with a hidden effect)")
    hidden = read_measurements(hidden_path)
    truth = hidden_truth(hidden.metadata)
    hidden_base = invert(Posterior.build(hidden, Model.from_string("paper")), seed=seed, progress=False)
    hidden_report, hidden_rungs = criticise(hidden, hidden_base, out / "hidden", str(hidden_path), seed)
    found = "found" if hidden_report["verdict"] == truth["hidden_effect"] or truth["hidden_effect"] in \
        hidden_report["ranking"][0].get("tied_with", []) else "NOT found"
    print(f"   verdict {hidden_report['verdict']}; the hidden effect was {truth['hidden_effect']} ({found})")

    print("4/6 what is missing from the paper's model on PTFE? diagnose -> ladder")
    ptfe_report, ptfe_rungs = criticise(data, inv, out / "ptfe", f"{source} (0.633 um, in-plane)", seed)
    print("   " + significance_statement(ptfe_report))
    # what the measurement says about itself, no model: its out-of-plane rows hold the mirror pairs and the
    # theta_i = theta_r rows that the plane of incidence lacks
    itself = reciprocity.symmetry_findings(reciprocity.symmetry_checks(measured))

    print("5/6 detecting a target of this material against the daytime sky: the paper's Table 3 as distributions")
    scenario = default_scenario()
    contrast = make_contrast_report(inv, scenario, out / "contrast", "corrected", seed=seed,
                                    label=str(out / "ptfe_paper"))
    for line in table3_lines(contrast):
        print("   " + line)
    limits = contrast["limit_through_chain"]
    limit_line = ("limiting magnitude: " + ", ".join(f"{label} {limits[key]['limiting_magnitude']:.2f}" for key, label in
                                                     (("printed", "the paper's Phi_s"), ("eq38", "eq 38 solved"),
                                                      ("chain", "the pass chain's detector")))
                  + " (the chain sums the spot's pixels: sqrt(k) more SNR)")
    print("   " + limit_line)
    sun = (contrast["sun"]["zenith_deg"], contrast["sun"]["azimuth_deg"])
    targets = {f"target {i + 1}": (c["zenith_deg"], c["azimuth_deg"]) for i, c in enumerate(scenario.cases)}
    save_figure(sky_maps_figure(RayleighSky(0.8), sun, targets), out / "contrast" / "sky_maps.png")
    save_figure(projection_distortion_figure(), out / "contrast" / "projections.png")

    print("6/6 the same material on a daytime pass: the ISS over the paper's site, light curves and P_d per detector")
    _, observed = observe_demo_pass(out / "ptfe_paper", out / "observe", seed)
    for line in observed:
        print("   " + line)

    sections = _demo_sections(out, forward_lines, summary, hidden_path, hidden, truth, hidden_report, hidden_rungs,
                              found, ptfe_report, ptfe_rungs, itself, scenario, contrast, limit_line, observed)
    write_text(out / "report.html", H.page("spacepol demo: PTFE", sections))
    print(f"wrote {out}/report.html (and ptfe_forward.csv, ptfe_dop.png, ptfe_paper/, hidden/, ptfe/, contrast/, observe/)")
