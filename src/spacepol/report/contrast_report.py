"""Files of ``invert-mcmc contrast``: contrast.json, table3.md, contrast_histograms.png, report.html."""

from __future__ import annotations

from pathlib import Path

from ..io.atomic import atomic_path, save_figure, write_json
from . import html as H
from .sky_figures import contrast_histograms
from ..infer.run_summary import RunSummary

QUANTITIES = [("target_dop", "target DOP", "{:.3f}"), ("sky_dop", "sky DOP", "{:.3f}"),
              ("limiting_magnitude", "limiting magnitude", "{:.2f}"), ("intensity_contrast", "raw intensity contrast", "{:.4f}"),
              ("polarization_contrast", "polarization contrast", "{:.3f}")]


def table3_lines(report: dict) -> list[str]:
    """Table 3 as a Markdown table: each case's quantities as median [5 %, 95 %] and the input that dominates the
    spread."""
    head = "| case | " + " | ".join(label for _, label, _ in QUANTITIES) + " | spread dominated by |"
    lines = [head, "|" + "---|" * (len(QUANTITIES) + 2)]
    for row in report["rows"]:
        cells = [f"{fmt.format(row[k]['median'])} [{fmt.format(row[k]['q05'])}, {fmt.format(row[k]['q95'])}]"
                 for k, _, fmt in QUANTITIES]
        lines.append(f"| {row['case']} | " + " | ".join(cells) + f" | {row['dominant_input']['polarization_contrast']} |")
    return lines


def dominance_paragraph(report: dict) -> str:
    """Per case, which input (material, geometry, sky) dominates the polarization contrast's spread, in words."""
    parts = []
    for row in report["rows"]:
        w = row["dominant_input"]["widths_90"]
        order = sorted(w, key=lambda n: -w[n]["polarization_contrast"])
        parts.append(f"{row['case']}: the 90 % width of the polarization contrast is {w[order[0]]['polarization_contrast']:.3f} "
                     f"when only the {order[0]} varies, against {w[order[1]]['polarization_contrast']:.3f} ({order[1]}) and "
                     f"{w[order[2]]['polarization_contrast']:.3f} ({order[2]}); the {order[0]} dominates.")
    return " ".join(parts)


def make_contrast_report(result, scenario, out: Path, reading: str = "corrected", draws: int = 20000, seed: int = 0,
                         extrapolate: bool = False, label: str | None = None) -> dict:
    """Propagate a run's Result (``infer.result``) through the scenario and write the files; returns contrast.json's
    content. ``extrapolate``: allow a scenario wavelength outside a multi-wavelength run's measured range;
    ``label``: how the report names the run (its folder)."""
    from ..detect.contrast import contrast_of

    report, per_case = contrast_of(result, scenario, seed, draws, reading, extrapolate)
    write_contrast_report(report, per_case, out, label or result.summary.model,
                          assumptions(result.summary, scenario, report["material"]))
    return report


def assumptions(summary: RunSummary, scenario, material: dict | None = None) -> list[str]:
    """What the contrast assumed (geometry, material rule, sky model, radiometry), one sentence each."""
    t, sky_ = scenario.target, scenario.sky
    return [
        f"Target DOP from the posterior of {summary.model} at theta_i {t['theta_i_deg']:g} deg, dphi {t['dphi_deg']:g} deg, "
        f"theta_r uniform in [{t['theta_r_low_deg']:g}, {t['theta_r_high_deg']:g}] deg (the paper's Figure 9 range), "
        "unless a case fixes theta_r_deg.",
        f"Material at {material['wavelength_um']:g} um: {material['rule']}." if material else
        "The material's posterior is used as measured; no dispersion to the 1.5-1.8 um band is modelled.",
        f"Sky DOP from the {sky_['model']} model with P_max uniform in [{sky_['p_max_low']:g}, {sky_['p_max_high']:g}] "
        "(a clear sky peaks near 0.7-0.8), sun from astropy for the scenario's site and time.",
        f"Limiting magnitude from eq 39 (angstrom, per cm^2) at Phi_s = {scenario.instrument['limit_flux_photons_m2_s']:g} "
        f"photons m^-2 s^-1; raw contrast against a sky of {scenario.instrument['sky_magnitude']:g} mag (implied by Table 3, "
        "not stated in the paper).",
    ]


def write_contrast_report(report: dict, draws: dict, out: Path, run_dir: str, assumptions: list[str]) -> None:
    """contrast.json (``report`` completed with the dominance paragraph and the assumptions), table3.md,
    contrast_histograms.png (``draws``: {case: {quantity: draws}}) and report.html in ``out``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    report["dominance"] = dominance_paragraph(report)
    report["assumptions"] = assumptions
    save_figure(contrast_histograms(draws), out / "contrast_histograms.png")
    lines = table3_lines(report)
    with atomic_path(out / "table3.md") as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    write_json(out / "contrast.json", report)
    rad = report["radiometry"]
    rows = [[r["case"]] + [f"{r[k]['median']:.4g} [{r[k]['q05']:.4g}, {r[k]['q95']:.4g}]" for k, _, _ in QUANTITIES]
            for r in report["rows"]]
    paper = [[p["case"], f"{p['sky_dop']['paper']}", f"{p['limiting_magnitude']['paper']}",
              f"{p['intensity_contrast']['paper']}", f"{p['polarization_contrast']['paper']}",
              "; ".join(f"{k}: {'reproduced' if v['reproduced'] else 'not reproduced'}" for k, v in p.items() if isinstance(v, dict))]
             for p in report["paper_table3"]]
    sections = [
        ("Posterior and scenario", H.paragraph(
            f"Posterior of {run_dir}; scenario {report['scenario']}; sun at zenith {report['sun']['zenith_deg']:.2f} deg, "
            f"azimuth {report['sun']['azimuth_deg']:.2f} deg (astropy); reading '{report['reading']}'; {report['draws']} draws.")
         + H.bullets(assumptions)),
        ("Table 3 as distributions (median [5 %, 95 %])", H.table(["case"] + [label for _, label, _ in QUANTITIES], rows)
         + H.paragraph(report["dominance"])
         + H.image(H.png_file_to_data_uri(out / "contrast_histograms.png"))),
        ("Radiometry at the detection limit (eqs 35-38, Table 2)", H.table(
            ["N_s (e-)", "N_B (e-)", "noise (e-)", "SNR", "flux for the required SNR (photons m^-2 s^-1)"],
            [[f"{rad['N_s']:.1f}", f"{rad['N_B']:.2e}", f"{rad['noise']:.2f}", f"{rad['snr']:.2f}",
              f"{rad['limit_flux_for_required_snr']:.4g}"]])),
        ("The limit through the pass chain's detector (observe)", _chain_paragraph(report)),
        ("The paper's Table 3 recomputed from its own inputs", H.table(
            ["case", "sky DOP", "limiting magnitude", "raw contrast", "polarization contrast", "verdict"], paper)
         + H.bullets([f"{p['case']} / {k}: {v['why']}" for p in report["paper_table3"] for k, v in p.items() if isinstance(v, dict)])),
    ]
    with atomic_path(out / "report.html") as tmp:
        tmp.write_text(H.page("spacepol contrast: detecting the target against the daytime sky", sections), encoding="utf-8")


def _chain_paragraph(report: dict) -> str:
    """The limiting magnitude three ways: the printed Phi_s (this report's), eq 38 solved, the pass chain's detector."""
    chain = report.get("limit_through_chain")
    if not chain:
        return H.paragraph("Not computed.")
    rows = [[label, f"{chain[key]['limit_flux_photons_m2_s']:.4g}", f"{chain[key]['limiting_magnitude']:.2f}"]
            for key, label in (("printed", "the paper's printed Phi_s (the table above)"),
                               ("eq38", "eq 38 solved for the required SNR"),
                               ("chain", "the pass chain's intensity detector (observe), Table 2 as its camera"))]
    return (H.table(["limit", "target flux at the aperture (photons m^-2 s^-1)", "limiting magnitude"], rows)
            + H.paragraph("Table 3's target and sky DOP are the chain's at this geometry (tests). The limits differ: "
                          + chain["why"]))
