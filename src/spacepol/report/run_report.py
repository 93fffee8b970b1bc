"""Files of ``invert-mcmc run``: summary.json, posterior.nc, corner.png, fit.png, residuals.png,
residual_trends.png, report.html."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..infer.draws_result import EXPLAINED_NOISE_RATIO, noise_findings
from ..io.atomic import save_figure, write_text
from . import html as H
from ..infer.residuals import analyse
from .criticism_figures import residual_trends_figure
from ..infer.identifiability import bound_finding
from .inversion_figures import corner_figure, fit_figure, mueller_residual_figure, residual_figure


def truths_from_metadata(metadata: dict) -> dict:
    """{parameter: true value} from a synthetic file's ``truth_NAME`` metadata (empty for real data)."""
    out = {}
    for key, value in metadata.items():
        if key.startswith("truth_"):
            try:
                out[key[6:]] = float(value)
            except ValueError:
                pass
    return out


def compare_with_references(result, references: dict) -> dict:
    """Where each known value falls in the posterior, and what that means."""
    flat = result.flat_samples()
    out = {}
    for name, value in references.items():
        x = flat[:, result.names.index(name)]
        pct = float(100 * np.mean(x < value))
        lo, med, hi = np.percentile(x, [5, 50, 95])
        consistent = 5.0 <= pct <= 95.0
        if consistent:
            text = (f"{name}: the reference {value:g} lies inside the 90 % interval [{lo:.4g}, {hi:.4g}] "
                    f"(at the {pct:.0f}th percentile): data, model and reference agree.")
        else:
            text = (f"{name}: the posterior (median {med:.4g}, 90 % [{lo:.4g}, {hi:.4g}]) excludes the reference "
                    f"{value:g} (which sits at the {pct:.1f}th percentile). The data are precise enough to tell, "
                    f"so it is the model that is wrong: a physical effect present in the data is missing and "
                    f"{name} moves to absorb it. Look at the residual structure (residuals.png) and compare models with "
                    f"an added effect (e.g. --model paper+polarized_diffuse).")
        out[name] = {"value": value, "percentile": pct, "consistent": consistent, "explanation": text}
    return out


def write_run_report(inv, out: Path, data_path: str, notes: list[str] | None = None, references: dict | None = None) -> dict:
    """A run's files in ``out``: corner, fit and residual figures, posterior.nc and summary.json (``Result.save``),
    report.html; returns the summary."""
    out.mkdir(parents=True, exist_ok=True)
    posterior, result, summary = inv.posterior, inv.draws, inv.summary
    if references:
        summary.references = compare_with_references(result, references)
        notes = list(notes or []) + [r["explanation"] for r in summary.references.values()]
    truths = truths_from_metadata(posterior.likelihood.data.metadata)
    figures = {
        "corner.png": corner_figure(result, truths),
        "fit.png": fit_figure(posterior, result),
        "residuals.png": residual_figure(posterior, result),
        "residual_trends.png": residual_trends_figure(analyse(posterior, result.flat_samples())),
    }
    if "m12" in posterior.likelihood.observables:
        figures["residuals_mueller.png"] = mueller_residual_figure(posterior, result)
    for name, fig in figures.items():
        save_figure(fig, out / name)
    inv.save(out)  # posterior.nc and summary.json
    write_text(out / "report.html", _html(inv, data_path, out, figures, truths, notes or []))
    return summary


def _html(inv, data_path, out, figures, truths, notes) -> str:
    def png(name):  # the saved file, embedded (drawing a figure again costs as much as the first time)
        return H.png_file_to_data_uri(out / name)

    s = inv.summary
    diag, fit = s.diagnostics, s.fit
    rows = []
    for name, q in s.parameters.items():
        truth = truths.get(name)
        flagged = any(f["parameter"] == name for f in s.at_bound)
        chain = diag.get("per_parameter", {}).get(name)  # None for importance-weighted draws (no chains)
        rows.append([name + (" (at a bound)" if flagged else ""), f"{q['median']:.4g}", f"[{q['q05']:.4g}, {q['q95']:.4g}]", f"[{q['q16']:.4g}, {q['q84']:.4g}]",
                     f"{chain['rhat']:.4f}" if chain else "n/a", f"{chain['ess_bulk']:.0f}" if chain else "n/a",
                     "" if truth is None else f"{truth:.4g}", s.priors.get(name, "")])
    for name, q in s.derived.items():  # implied by a dispersion law, not sampled themselves
        rows.append([f"{name} (from the dispersion law)", f"{q['median']:.4g}", f"[{q['q05']:.4g}, {q['q95']:.4g}]",
                     f"[{q['q16']:.4g}, {q['q84']:.4g}]", "", "", "" if truths.get(name) is None else f"{truths[name]:.4g}", ""])
    quality = inv.diagnostics
    converged = quality.converged and not quality.capped
    if quality.engine == "laplace-is":
        verdict = (f"Laplace approximation corrected by importance sampling: Pareto k {quality.pareto_k:.2f}, "
                   f"{quality.ess_min:.0f} effective draws (trusted: k <= 0.7, >= 400 draws, weights not collapsed).")
    else:
        verdict = (f"Converged ({quality.engine}): R-hat <= 1.01 and ESS >= 400 for every parameter." if converged else
                   "NOT converged by the R-hat <= 1.01 / ESS >= 400 standard; run longer (--steps) before trusting "
                   "the intervals.")
    if s.laplace_refused:
        verdict = f"The Laplace approximation was refused ({s.laplace_refused}); emcee sampled instead. " + verdict
    if s.log_evidence:
        verdict += f" Log evidence ln Z = {s.log_evidence['value']:.2f} +- {s.log_evidence['error']:.2f}."
    if s.sampler.get("missed_mode"):
        verdict += f" NOT the whole posterior: {s.sampler['missed_mode']['finding']}."
    if s.sampler.get("explorations_ended_early"):
        verdict += (f" In {s.sampler['explorations_ended_early']} nested-sampling replicate(s) the exploration added no "
                    "shell over a long run and was ended where it stood: ln Z and the draws are rough.")
    if s.sampler.get("capped"):
        verdict += f" The chain hit the step cap ({s.sampler['steps']} steps) before reaching 50 autocorrelation times."
    sections = [
        ("Data and model", H.paragraph(
            f"{data_path}: {s.n_observations} observations ({', '.join(s.observables)}); model {s.model}; "
            f"seed {s.seed}; {s.seconds:.1f} s.")),
        ("Parameters", H.table(["parameter", "median", "90 % interval", "68 % interval", "R-hat", "ESS bulk", "truth", "prior"], rows)
         + (H.bullets([bound_finding(f) for f in s.at_bound]))),
        ("Convergence", H.paragraph(verdict) + H.table(
            ["R-hat max", "ESS min (bulk/tail)", "tau max (steps)", "acceptance", "walkers", "steps", "burn-in", "thin"],
            [[_fmt(quality.rhat_max, "{:.4f}"), _fmt(quality.ess_min, "{:.0f}"), _fmt(quality.tau_max, "{:.1f}"),
              _fmt(diag.get("acceptance"), "{:.2f}"), *(s.sampler.get(k, "n/a") for k in ("walkers", "steps", "burn_in", "thin"))]])),
        ("What the data determine", H.bullets(s.identifiability["findings"])
         + (H.paragraph("Where the chain started:") + H.bullets(s.start_search["findings"])
            if s.start_search.get("findings") else "")),
        ("Fit", H.table(["RMSE (DOP)", "reduced chi^2", "ELPD-LOO", "SE"],
                        [[_fmt(fit["rmse_dop"]), f"{fit['chi2_red']:.3f}", f"{fit['elpd_loo']:.2f}", f"{fit['elpd_loo_se']:.2f}"]])
         + (H.paragraph("PSIS-LOO Pareto k > 0.7 (LOO unreliable there, the fit is sensitive to these points): "
                        + ", ".join(s.pareto_k_bad)) if s.pareto_k_bad else "")
         + H.bullets(s.residual_findings)
         + (H.paragraph("Noise the data measure themselves (reciprocal pairs, repeated geometries) against the noise the "
                        "fit inferred; a model explains the data only where the ratio is at most "
                        f"{EXPLAINED_NOISE_RATIO:g}:") + H.bullets(noise_findings(s.noise)) if s.noise else "")
         + H.image(png("fit.png"), "Data, posterior median and 90 % band of the prediction, "
                   "per observable (rows) and incidence angle (columns).")
         + H.image(png("residuals.png"), "Standardised residuals; dotted lines at +-2.")
         + (H.image(png("residuals_mueller.png"), "Residuals laid out as the Mueller matrix.")
            if "residuals_mueller.png" in figures else "")
         + H.image(png("residual_trends.png"),
                   "Residuals against each angle and the DOP level, with Spearman's rho (red: p < 0.01).")),
        ("Posterior", H.image(png("corner.png"), "Corner plot; 5/50/95 % quantiles; truths in red when known.")),
    ]
    if notes:
        sections.insert(4, ("Notes", H.bullets(notes)))
    return H.page(f"spacepol inversion: {s.model}", sections)


def _fmt(x, pattern: str = "{:.4g}"):
    return "n/a" if x is None or (isinstance(x, float) and not np.isfinite(x)) else pattern.format(x)
