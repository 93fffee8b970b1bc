"""The PTFE study (issue 11, item 7): what the library makes of NIST's measured Mueller-matrix BRDF of
sintered PTFE (T. A. Germer, Appl. Opt. 56, 9333, 2017), the whole file: every geometry, every
wavelength, all 15 normalised Mueller elements and the BRDF.

    python studies/ptfe_study.py [--wavelength-um all] [--rounds 3] [--top 1] [--model paper] [--joint all]
                                 [--hold-index 1.35] [--seed 0] [--out reports/ptfe]

``--joint all`` refits the loop's first and last models jointly over those wavelengths (n per wavelength,
geometry shared) after a loop run at fewer wavelengths (a loop at all four costs about an hour a round here).

1. The data's own reciprocity on the rows whose swapped geometry was measured (criticism/reciprocity.py).
2. The criticism loop from the paper's model (diagnose, one round at a time, continuing from the change
   taken): per round the ELPD-LOO, the inferred noise per Mueller element group, the residual structure
   per element (runs test along the angle sweeps), the parameters at a prior bound, n(lambda) and how
   far the model's predictions are from reciprocal.
3. n(lambda) posteriors against PTFE's known index: 1.35 at the sodium D line (Polymer Handbook, 4th ed.,
   Brandrup, Immergut and Grulke eds., Wiley 1999, section VI; sintered PTFE's crystalline and amorphous
   phases span about 1.33-1.38), weakly dispersive over 0.35-1.06 um for a fluoropolymer.
4. What remains unexplained, said plainly (report.md): per round the misfit = inferred noise / the noise the
   data measure themselves (reciprocal pairs, ``infer/measured_noise.py``) per element group, the residual RMS per
   element; with ``--hold-index 1.35`` the final model refitted with n held at PTFE's index at every wavelength,
   and what that costs, element by element (which structure forces n away from the material's value).

After each round the report is rewritten, so an interrupted study keeps what it measured.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from spacepol.criticism import reciprocity  # noqa: E402
from spacepol.criticism.rounds import as_rungs, diagnose_rounds  # noqa: E402
from spacepol.infer.diagnostics import inferred_noise_levels  # noqa: E402
from spacepol.io import read_measurements  # noqa: E402
from spacepol.io.atomic import save_figure, write_json, write_text  # noqa: E402
from spacepol.paths import bundled  # noqa: E402
from spacepol.physics import Model  # noqa: E402
from spacepol.physics.spectral import SpectralModel  # noqa: E402
from spacepol.report.inversion_figures import mueller_residual_figure  # noqa: E402

PTFE_INDEX, PTFE_INDEX_BAND = 1.35, (1.33, 1.38)
SOURCE = ("PTFE's index: n_D = 1.35 (Polymer Handbook, 4th ed., Brandrup, Immergut, Grulke eds., Wiley 1999; Groh & "
          "Zimmermann, Macromolecules 24, 6660 (1991)); 1.33-1.38 spans its crystalline and amorphous phases")


def load(wavelengths: str, in_plane: bool = False):
    data = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv"))
    if wavelengths != "all":
        data = data.at_wavelengths([float(w) for w in wavelengths.split(",")])
    return data.in_plane() if in_plane else data


def model_for(data, spec: str):
    model = Model.from_string(spec)
    lams = np.unique(data.wavelength_um)
    return SpectralModel(model, lams) if len(lams) > 1 else model


def medians(inv) -> dict:
    names = {p.name for p in inv.posterior.likelihood.model.parameters}
    return {k: v["median"] for k, v in inv.summary.parameters.items() if k in names}


def index_posteriors(inv, data) -> dict:
    """{wavelength label: quantiles of n there} (n itself at one wavelength)."""
    p = inv.summary.parameters | inv.summary.derived
    labels = [f"{w:g}" for w in np.unique(data.wavelength_um)]
    if len(labels) == 1:
        return {labels[0]: p["n"]} if "n" in p else {}
    return {lab: p[f"n@{lab}"] for lab in labels if f"n@{lab}" in p}


def element_rms(inv) -> dict:
    """{channel: RMS of measured minus the posterior-median prediction} (relative for the BRDF, absolute for m_ij)."""
    from spacepol.infer.inference_data import median_fit

    lik = inv.posterior.likelihood
    mu, _ = median_fit(inv.posterior, inv.draws.flat_samples())
    return {ch: float(np.sqrt(np.mean(np.square(lik.residual(ch, mu[ch]))))) for ch in lik.observables}


def rung_record(step: dict, inv, data) -> dict:
    s = inv.summary
    runs = s.residual_structure.get("runs", {})
    return {
        "noise": {k: {f: v[f] for f in ("inferred", "measured", "ratio")} for k, v in s.noise.items()},
        "element_rms": element_rms(inv),
        "model": step["model"], "change": step["change"], "delta_elpd": step["delta_elpd"],
        "delta_elpd_se": step["delta_elpd_se"], "tied_with": step.get("tied_with", []),
        "elpd_loo": s.fit["elpd_loo"], "elpd_loo_se": s.fit["elpd_loo_se"], "rmse_dop": s.fit["rmse_dop"],
        "inferred_noise": inferred_noise_levels(s),
        "runs_z": {ch: r["z"] for ch, r in runs.items()},
        "structured": bool(s.residual_structure.get("structured")),
        "at_bound": [f"{b['parameter']} at its {b['side']} bound {b['bound']:g}" for b in s.at_bound],
        "n": index_posteriors(inv, data),
        "reciprocity": reciprocity.model_violation(inv.posterior.likelihood.model, medians(inv), data.geometry),
        "rhat_max": s.diagnostics["rhat_max"], "seconds": s.seconds,
    }


def rounds_figure(rungs: list[dict]):
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.2), constrained_layout=True)
    x = np.arange(len(rungs))
    labels = [r["change"] or r["model"] for r in rungs]
    a.errorbar(x, [r["elpd_loo"] for r in rungs], [r["elpd_loo_se"] for r in rungs], marker="o", capsize=3)
    a.set_ylabel("ELPD-LOO (higher is better)")
    for name in sorted({n for r in rungs for n in r["inferred_noise"]}):
        b.plot(x, [r["inferred_noise"].get(name, np.nan) for r in rungs], marker="o", label=name)
    b.set_yscale("log")
    b.set_ylabel("inferred noise (posterior median)")
    b.legend(fontsize=8)
    for ax in (a, b):
        ax.set_xticks(x, labels, rotation=20, ha="right", fontsize=8)
        ax.grid(alpha=0.3)
    fig.suptitle("PTFE: the criticism loop, round by round")
    return fig


def index_figure(rungs: list[dict]):
    fig, ax = plt.subplots(figsize=(7, 4.2), constrained_layout=True)
    ax.axhspan(*PTFE_INDEX_BAND, color="0.85", label=f"PTFE {PTFE_INDEX_BAND[0]}-{PTFE_INDEX_BAND[1]} (n_D = {PTFE_INDEX})")
    for i, r in enumerate(rungs):
        lams = np.array([float(k) for k in r["n"]])
        if not lams.size:
            continue
        q = list(r["n"].values())
        mid = np.array([v["median"] for v in q])
        err = np.array([[v["median"] - v["q05"] for v in q], [v["q95"] - v["median"] for v in q]])
        ax.errorbar(lams * (1 + 0.01 * (i - len(rungs) / 2)), mid, err, marker="o", capsize=3, label=r["change"] or r["model"])
    ax.set_xlabel("wavelength (um)")
    ax.set_ylabel("n: median and 90 % interval")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    ax.set_title("PTFE's refractive index: posterior per round against the known value")
    return fig


def structure_figure(rungs: list[dict]):
    channels = list(dict.fromkeys(ch for r in rungs for ch in r["runs_z"]))
    z = np.array([[r["runs_z"].get(ch, np.nan) for ch in channels] for r in rungs])
    fig, ax = plt.subplots(figsize=(10, 0.6 * len(rungs) + 1.8), constrained_layout=True)
    im = ax.imshow(z, cmap="RdBu", vmin=-20, vmax=20, aspect="auto")
    ax.set_xticks(range(len(channels)), channels, fontsize=8)
    ax.set_yticks(range(len(rungs)), [r["change"] or r["model"] for r in rungs], fontsize=8)
    for (i, j), v in np.ndenumerate(z):
        if np.isfinite(v):
            ax.text(j, i, f"{v:.0f}", ha="center", va="center", fontsize=7)
    fig.colorbar(im, ax=ax, label="runs-test z (< -2.6: smooth misfit; > 2.6: alternating; p < 0.01)")
    ax.set_title("Residual structure per element and round (noise: |z| < 2.6)")
    return fig


def findings(rungs: list[dict], data_recip: dict) -> list[str]:
    last = rungs[-1]
    out = []
    n = last["n"]
    covered = [lab for lab, q in n.items() if q["q05"] <= PTFE_INDEX_BAND[1] and q["q95"] >= PTFE_INDEX_BAND[0]]
    words = ", ".join(f"n@{lab} {q['median']:.3f} [{q['q05']:.3f}, {q['q95']:.3f}]" for lab, q in n.items())
    below_one = [lab for lab, q in n.items() if q["q95"] < 1.0]
    if below_one:
        out.append(f"n < 1 at {', '.join(below_one)} um (90 % interval): impossible for a bulk polymer in the visible "
                   f"and near infrared; the fitted 'interface' is not PTFE's surface but whatever lets the facet model "
                   f"mimic the measured polarization.")
    if len(covered) == len(n) and n:
        out.append(f"The final model's n posteriors ({words}) overlap PTFE's known index band {PTFE_INDEX_BAND}.")
    else:
        out.append(f"The final model's n posteriors ({words}) do not reach PTFE's known index band {PTFE_INDEX_BAND} "
                   f"at {len(n) - len(covered)} of {len(n)} wavelengths: n is absorbing a misfit, not measuring the surface.")
    smooth = [ch for ch, z in last["runs_z"].items() if z < -2.6]
    alternating = [ch for ch, z in last["runs_z"].items() if z > 2.6]
    if smooth:
        out.append(f"Residuals remain smooth along the sweeps (runs-test z < -2.6: fewer sign changes than noise) in "
                   f"{len(smooth)} of {len(last['runs_z'])} channels: {', '.join(smooth)}: the final model still misses "
                   f"physics there.")
    if alternating:
        out.append(f"Residuals change sign more often than noise (z > 2.6) in {', '.join(alternating)}: a misfit of "
                   f"alternating sign between neighbouring rows, also structure (m13, m14, m23, m24, m31, m32, m41, m42 are "
                   f"odd in dphi: a misfit that flips sign with dphi alternates wherever rows of opposite dphi meet).")
    if not smooth and not alternating:
        out.append("No channel's residuals show structure along the sweeps: the final model leaves noise.")
    if last["at_bound"]:
        out.append("Parameters at a prior bound (the fit is unphysical there; their intervals are not measurements): "
                   + "; ".join(last["at_bound"]) + ".")
    ratios = {k: v["ratio"] for k, v in last.get("noise", {}).items()}
    if ratios:
        above = {k: r for k, r in ratios.items() if r > 1.5}
        out.append("Misfit = inferred noise / the noise the data measure themselves (reciprocal pairs): "
                   + ", ".join(f"{k} {r:.2f}" for k, r in ratios.items())
                   + (f": {', '.join(above)} above 1.5, so the model does not explain these elements; the inferred noise "
                      "there is model misfit." if above else ": every group within 1.5 of the measurement's noise."))
    rec = last["reciprocity"]
    out.append(f"Reciprocity of the final model at its posterior median: BRDF changes by a median "
               f"{100 * rec['brdf_relative_median']:.1f} % (95th percentile {100 * rec['brdf_relative_p95']:.1f} %) when "
               f"source and detector swap; normalised elements by up to {rec['element_p95']:.3f} (95th percentile). "
               f"The measurement's own reciprocal pairs (all wavelengths, {data_recip.get('n_pairs', 0)} pairs): BRDF "
               f"differs by a median {100 * data_recip.get('brdf_relative_median', float('nan')):.1f} %, normalised "
               f"elements by {data_recip.get('element_rms', float('nan')):.3f} RMS, i.e. a measurement noise of about "
               f"{data_recip.get('element_rms', float('nan')) / np.sqrt(2):.3f} per element: the data are reciprocal "
               f"within it (a non-reciprocal model term cannot be what the sample does), and an inferred element noise "
               f"above it (" + ", ".join(f"{k} {v:.3f}" for k, v in rungs[-1]["inferred_noise"].items() if k.startswith("sigma_m"))
               + ") is model misfit, not the polarimeter.")
    return out


def held_findings(final: dict, held: dict) -> list[str]:
    """What holding n at PTFE's index costs the final model, element by element."""
    worse = sorted(held["element_rms"], key=lambda ch: final["element_rms"][ch] - held["element_rms"][ch])
    change = ", ".join(f"{ch} {final['element_rms'][ch]:.4f} -> {held['element_rms'][ch]:.4f}" for ch in worse[:4])
    same = [ch for ch in held["element_rms"] if abs(held["element_rms"][ch] - final["element_rms"][ch]) < 0.1 * final["element_rms"][ch]]
    ratios = ", ".join(f"{k} {v['ratio']:.2f}" for k, v in held.get("noise", {}).items())
    return [f"With n held at {held['held_index']} at every wavelength, {held['model']} changes ELPD-LOO by "
            f"{held['delta_elpd']:+.0f} +- {held['delta_elpd_se']:.0f}; the residual RMS rises most in {change}"
            + (f"; misfit ratios {ratios}" if ratios else "")
            + f". Within 10 % either way: {', '.join(same) or 'none'} (structure that n does not touch)."]


def symmetry_findings(symmetry: dict, rungs: list[dict]) -> list[str]:
    """What the measurement's own symmetries say, beside the noise the reciprocal pairs measured in the last round."""
    measured = {k.removeprefix("sigma_m_"): v["measured"] for k, v in rungs[-1].get("noise", {}).items()}
    return reciprocity.symmetry_findings(symmetry, measured)


def write_report(out: Path, meta: dict, rungs: list[dict], data_recip: dict, done: bool, joint=(), held=None,
                 symmetry: dict | None = None) -> None:
    symmetry = symmetry or {}
    write_json(out / "study.json", {"meta": meta, "data_reciprocity": data_recip, "data_symmetry": symmetry, "rounds": rungs,
                                    "joint": list(joint), "held_index": held, "complete": done})
    save_figure(rounds_figure(rungs), out / "rounds.png")
    save_figure(index_figure(list(joint) or rungs), out / "n_lambda.png")
    save_figure(structure_figure(rungs), out / "residual_structure.png")
    plt.close("all")
    lines = [f"# PTFE study: {meta['data']}", "",
             f"Re-made by `python studies/ptfe_study.py {meta['arguments']}` ({meta['minutes']:.0f} min on {meta['machine']}); "
             f"{'complete' if done else 'PARTIAL: interrupted or still running'}.", "",
             f"{meta['rows']} geometries x ({', '.join(meta['observables'])}) = {meta['numbers']} measured numbers at "
             f"{meta['wavelengths']} um. {SOURCE}.", "",
             "## Findings", ""] + [f"- {f}" for f in findings(rungs, data_recip)] + (
             [f"- Jointly over {meta['joint_wavelengths']} um ({joint[-1]['model']}): "
              + " ".join(f for f in findings(joint, data_recip) if f.startswith(("n < 1", "The final model's n")))]
             if joint else []) + ([f"- {f}" for f in held_findings(rungs[-1], held)] if held else []) + [
             f"- {f}" for f in symmetry_findings(symmetry, rungs)] + [
             "", "## Rounds", "",
             "| round | change | delta ELPD | ELPD-LOO | inferred noise | n(lambda) median | at bound | reciprocity (BRDF median, elements p95) |",
             "|---|---|---|---|---|---|---|---|"]
    for i, r in enumerate(rungs):
        delta = "" if r["delta_elpd"] is None else f"{r['delta_elpd']:+.1f} +- {r['delta_elpd_se']:.1f}"
        noise = ", ".join(f"{k} {v:.3g}" for k, v in r["inferred_noise"].items())
        n = ", ".join(f"{lab}: {q['median']:.3f}" for lab, q in r["n"].items())
        rec = r["reciprocity"]
        lines.append(f"| {i} | {r['change'] or r['model']} | {delta} | {r['elpd_loo']:.0f} +- {r['elpd_loo_se']:.0f} | {noise} | {n} | "
                     f"{'; '.join(r['at_bound']) or 'none'} | {100 * rec['brdf_relative_median']:.1f} %, {rec['element_p95']:.3f} |")
    if joint:
        lines += ["", f"## The first and last models jointly over {meta['joint_wavelengths']} um", "",
                  "| model | ELPD-LOO | inferred noise | n(lambda): median [90 %] | at bound |", "|---|---|---|---|---|"]
        for r in joint:
            noise = ", ".join(f"{k} {v:.3g}" for k, v in r["inferred_noise"].items())
            n = ", ".join(f"{lab}: {q['median']:.3f} [{q['q05']:.3f}, {q['q95']:.3f}]" for lab, q in r["n"].items())
            lines.append(f"| {r['model']} | {r['elpd_loo']:.0f} +- {r['elpd_loo_se']:.0f} | {noise} | {n} | {'; '.join(r['at_bound']) or 'none'} |")
    rows = rungs + ([held] if held else [])
    groups = list(dict.fromkeys(k for r in rows for k in r.get("noise", {})))
    if groups:
        lines += ["", "## Misfit = inferred noise / measured noise, per element group", "",
                  "| round | " + " | ".join(groups) + " |", "|---|" + "---|" * len(groups)]
        for i, r in enumerate(rows):
            cells = [f"{r['noise'][g]['inferred']:.4f} / {r['noise'][g]['measured']:.4f} = {r['noise'][g]['ratio']:.2f}"
                     if g in r.get("noise", {}) else "" for g in groups]
            lines.append(f"| {i if r is not held else 'n held'} | " + " | ".join(cells) + " |")
    channels = list(dict.fromkeys(ch for r in rungs for ch in r.get("element_rms", {})))
    if channels:
        lines += ["", "## Residual RMS per element (BRDF relative), at the posterior median", "",
                  "| model | " + " | ".join(channels) + " |", "|---|" + "---|" * len(channels)]
        for r in rows:
            lines.append(f"| {r['change'] or r['model']} | " + " | ".join(f"{r['element_rms'].get(ch, float('nan')):.4f}" for ch in channels) + " |")
    lines += ["", "![rounds](rounds.png)", "", "![n(lambda)](n_lambda.png)", "", "![residual structure](residual_structure.png)", "",
              "![final residuals as the Mueller matrix](final_residuals_mueller.png)", ""]
    write_text(out / "report.md", "\n".join(lines) + "\n")


def main(argv=None) -> int:
    from spacepol import configure_process

    configure_process(small_calls=True)  # the settings the command line makes
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--wavelength-um", default="all")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--top", type=int, default=1, help="candidates confirmed by emcee per round")
    parser.add_argument("--model", default="paper", help="where the loop starts")
    parser.add_argument("--joint", default=None, metavar="all|LIST", help="refit the first and last models jointly here")
    parser.add_argument("--render-only", action="store_true", help="rewrite report.md and figures from OUT/study.json")
    parser.add_argument("--in-plane", action="store_true", help="the plane of incidence only (a quick look, not the study)")
    parser.add_argument("--hold-index", type=float, default=None, metavar="N",
                        help="refit the final model with n held at N at every wavelength (PTFE: 1.35)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="reports/ptfe")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.render_only:
        saved = json.loads((out / "study.json").read_text())
        studied = load(saved["meta"]["wavelengths"].replace(" ", ""), args.in_plane)
        write_report(out, saved["meta"], saved["rounds"], reciprocity.data_violation(load("all", args.in_plane)),
                     saved["complete"], saved.get("joint", ()), saved.get("held_index"), reciprocity.symmetry_checks(studied))
        return 0
    start = time.perf_counter()
    data = load(args.wavelength_um, args.in_plane)
    current = model_for(data, args.model)
    data_recip = reciprocity.data_violation(load("all", args.in_plane))  # the measurement's own check: every wavelength
    symmetry = reciprocity.symmetry_checks(data)  # at the wavelengths studied, as the measured noise is
    print(f"{len(data)} geometries at {sorted(set(np.round(data.wavelength_um, 3)))} um; data reciprocity {data_recip}", file=sys.stderr)
    rng = np.random.default_rng(args.seed)
    rungs, base, done = [], None, False
    for r in range(args.rounds):
        result = diagnose_rounds(data, current, rng, 1, seed=args.seed, top=args.top, base=base)
        fits = as_rungs(result)
        if not rungs:
            rungs.append(rung_record(result["rounds"][0], fits[0].inversion, data))
            observables = fits[0].inversion.posterior.likelihood.observables
        if len(fits) == 1:  # nothing significant: the loop stops here
            rungs[-1]["equivalent"] = result["rounds"][0].get("equivalent", [])
            rungs[-1]["better"] = result["rounds"][0].get("better", [])
            done = True
        else:
            rungs.append(rung_record(result["rounds"][1], fits[1].inversion, data))
            base = fits[1].inversion
            current = base.posterior.likelihood.model
        final = base or fits[0].inversion
        save_figure(mueller_residual_figure(final.posterior, final.draws), out / "final_residuals_mueller.png")
        meta = {"data": "NIST sintered PTFE Mueller BRDF (Germer 2017)", "arguments": " ".join(argv or sys.argv[1:]),
                "minutes": (time.perf_counter() - start) / 60, "machine": "2 cores", "rows": len(data),
                "observables": observables, "numbers": len(data) * len(observables),
                "wavelengths": ", ".join(f"{w:g}" for w in np.unique(data.wavelength_um))}
        write_report(out, meta, rungs, data_recip, (done or r == args.rounds - 1) and not args.joint and args.hold_index is None,
                     symmetry=symmetry)
        print(f"round {r + 1}: {rungs[-1]['change'] or 'no change'}; report rewritten in {out}", file=sys.stderr)
        if done:
            break
    held = None
    if args.hold_index is not None:
        from spacepol.infer.inversion import invert
        from spacepol.infer.posterior import Posterior
        from spacepol.priors import Fixed

        model = final.posterior.likelihood.model
        pinned = {p.name: Fixed(args.hold_index) for p in final.posterior.priors.parameters
                  if p.name == "n" or p.name.startswith("n@")}
        print(f"refitting {rungs[-1]['model']} with {', '.join(pinned)} held at {args.hold_index}", file=sys.stderr)
        inv = invert(Posterior.build(data, model, pinned), seed=args.seed, progress=False)
        diff = inv.loo["pointwise"] - final.loo["pointwise"]
        held = rung_record({"model": rungs[-1]["model"], "change": f"n held at {args.hold_index}",
                            "delta_elpd": float(diff.sum()), "delta_elpd_se": float(np.sqrt(len(diff) * np.var(diff)))},
                           inv, data) | {"held_index": args.hold_index}
        meta["minutes"] = (time.perf_counter() - start) / 60
        write_report(out, meta, rungs, data_recip, not args.joint, held=held, symmetry=symmetry)
    if args.joint:
        from spacepol.infer.inversion import invert
        from spacepol.infer.posterior import Posterior

        joint_data = load(args.joint, args.in_plane)
        meta["joint_wavelengths"] = ", ".join(f"{w:g}" for w in np.unique(joint_data.wavelength_um))
        joint = []
        for spec in dict.fromkeys([rungs[0]["model"], rungs[-1]["model"]]):
            print(f"joint fit of {spec} over {meta['joint_wavelengths']} um ({len(joint_data)} geometries)", file=sys.stderr)
            inv = invert(Posterior.build(joint_data, model_for(joint_data, spec)), seed=args.seed, progress=False)
            joint.append(rung_record({"model": spec, "change": f"joint: {spec}", "delta_elpd": None, "delta_elpd_se": None},
                                     inv, joint_data))
            meta["minutes"] = (time.perf_counter() - start) / 60
            write_report(out, meta, rungs, data_recip, len(joint) == 2 or rungs[0]["model"] == rungs[-1]["model"], joint, held,
                         symmetry)
    return 0


if __name__ == "__main__":
    sys.exit(main())
