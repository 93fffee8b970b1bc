"""NIST's PTFE (Germer, Appl. Opt. 56, 9333, 2017) under competing models, jointly at every wavelength, every row:
which model reaches the noise the measurement shows itself, and what each says about the index.

    python studies/ptfe_models.py [--wavelength-um all] [--in-plane] [--mask-anisotropic] [--noise-profile]
                                  [--models paper,...,specular+smith+subsurface+phase_matrix+polarization_memory]
                                  [--posterior laplace|emcee] [--max-steps 4000] [--search-every 1] [--seed 0]
                                  [--out reports/ptfe_models]

1. The noise the data measure themselves, per wavelength and Mueller element group (reciprocal pairs).
2. The sample's anisotropy from the data alone: per mirror pair (dphi, -dphi) the asymmetry chi^2 against that noise
   (``reciprocity.mirror_asymmetry``); with ``--mask-anisotropic`` the rows of pairs beyond the noise are left out.
   With ``--noise-profile`` each row's noise is the measurement's own (the reciprocal pairs' at its wavelength, the
   mirror pairs' rise with its exit angle) times one inferred factor per element group.
3. Per model: the posterior maximum (``find_optimum_profiled``; on every n-th row, then polished on all, with
   ``--search-every``), then diagnose's posterior (Laplace-IS where its
   checks trust it, else emcee up to ``--max-steps``), ELPD-LOO, the inferred noise against the measured one per
   group, and every index-like parameter told honestly (``infer.indices``: determined where its 90 % interval is
   narrower than 0.3; physical for porous PTFE inside [1.15, 1.45]).
4. A table ranking the models by ELPD-LOO with the SE of each difference, and a figure of where the best model's
   misfit sits (element x geometry, per wavelength, in units of the measured noise).
The report (``report.md``, ``study.json``) is rewritten after each model, with each model's pointwise ELPD-LOO in
``pointwise/``: the same command run again keeps the models already fitted under the same settings and fits the rest.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from spacepol.criticism.reciprocity import PROFILE_EDGES_DEG, mirror_asymmetry, mirror_scatter  # noqa: E402
from spacepol.errors import SpacepolError  # noqa: E402
from spacepol.infer.indices import INDEX_LIKE, index_findings  # noqa: E402
from spacepol.infer.inference_data import median_fit  # noqa: E402
from spacepol.infer.inversion import invert, laplace_fit  # noqa: E402
from spacepol.infer.optimum import find_optimum_on_every  # noqa: E402
from spacepol.infer.posterior import Posterior  # noqa: E402
from spacepol.io import read_measurements  # noqa: E402
from spacepol.io.atomic import save_figure, write_json, write_text  # noqa: E402
from spacepol.observables.mueller import GROUP_OF, GROUPS  # noqa: E402
from spacepol.paths import bundled  # noqa: E402
from spacepol.physics import Model  # noqa: E402
from spacepol.physics.spectral import SpectralModel, wavelength_label  # noqa: E402
from spacepol.priors import Fixed, Uniform  # noqa: E402

MODELS = ("paper,specular+smith+subsurface+volume,specular+smith+subsurface+phase_matrix,"
          "specular+smith+subsurface+phase_matrix+polarization_memory")
# sintered PTFE: grains of index 1.35 (Polymer Handbook, 4th ed., 1999), 30-40 % pores; an effective interface index
# between the porous surface's and the grains' (Germer, SPIE 10655, 2018)
PTFE_BAND = (1.15, 1.45)
GOAL_RATIO = 1.5


def load(wavelengths: str):
    """Every row of the file at ``wavelengths`` ("all" or a comma list)."""
    data = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv"))
    return data if wavelengths == "all" else data.at_wavelengths([float(w) for w in wavelengths.split(",")])


def measured_noise(data) -> dict:
    """{wavelength label: {group: the noise the reciprocal pairs measure}}."""
    out = {}
    for w in np.unique(data.wavelength_um):
        post = Posterior.build(data.at_wavelength(float(w)), Model.from_string("paper"), check=False)
        out[wavelength_label(w)] = {k.removeprefix("sigma_m_"): m.value for k, m in post.measured_noise.items()
                                    if k.startswith("sigma_m_")}
    return out


def anisotropy(data, noise: dict) -> dict:
    """{wavelength label: MirrorAsymmetry}, each against its wavelength's measured noise, rows in ``data``'s indexing."""
    out = {}
    for w in np.unique(data.wavelength_um):
        label = wavelength_label(w)
        rows = np.flatnonzero(data.wavelength_um == w)
        if set(noise.get(label, {})) >= {"pol", "lin", "circ"}:
            found = mirror_asymmetry(data.select(rows), noise[label])
            out[label] = (found, rows[found.rows])
    return out


def exit_scatter(data) -> dict:
    """{wavelength label: MirrorScatter}: the measurement's own spread per element group and exit-angle bin, from its
    mirror pairs (``reciprocity.mirror_scatter``); the reciprocal pairs, which give the noise the likelihood is
    compared with, lie at theta 30 and 45 deg only."""
    return {wavelength_label(w): mirror_scatter(data.at_wavelength(float(w))) for w in np.unique(data.wavelength_um)}


def measured_noise_profile(data, noise: dict) -> np.ndarray:
    """(3, N) for ``Dataset.mueller_noise_profile``: each row's group noise as the measurement shows it, the reciprocal
    pairs' noise at its wavelength times the mirror pairs' rise with the exit angle there
    (``MirrorScatter.noise_profile``), in ``profile_unit``. The likelihood's inferred level of each group over that
    unit is then one factor on the measured noise, the same at every wavelength and exit angle: 1 where the model
    leaves only the measurement's own noise."""
    out = np.empty((len(GROUPS), len(data)))
    for w in np.unique(data.wavelength_um):
        at = np.flatnonzero(data.wavelength_um == w)
        one = data.select(at)
        shape = mirror_scatter(one, PROFILE_EDGES_DEG).noise_profile(one)
        out[:, at] = shape * np.array([noise[wavelength_label(w)][g] for g in GROUPS])[:, None]
    return out / profile_unit(data, noise)[:, None]


def profile_unit(data, noise: dict) -> np.ndarray:
    """Per group, the mean over ``data``'s wavelengths of the reciprocal pairs' noise: ``measured_noise_profile`` is
    in its units, so that the inferred level stays a noise (inside its prior) and level / unit is the factor on the
    measured noise."""
    return np.array([np.mean([noise[wavelength_label(w)][g] for w in np.unique(data.wavelength_um)]) for g in GROUPS])


def exit_ratios(z: dict, data, noise: dict, scatter: dict) -> dict:
    """{wavelength: {group: [RMS residual / the mirror pairs' spread, per exit-angle bin]}}: ``z`` (residuals over the
    reciprocal pairs' noise, ``standardised``) back in the elements' units, against the spread the measurement shows
    at those exit angles itself. 1 where the model leaves only what the data scatter by."""
    out = {}
    for w in np.unique(data.wavelength_um):
        label = wavelength_label(w)
        at = data.wavelength_um == w
        bins = scatter[label].bin_of(np.asarray(data.theta_r, float)[at])
        out[label] = {}
        for g in ("pol", "lin", "circ"):
            residual = np.stack([z[ch][at] for ch in z if GROUP_OF[ch] == g]) * noise[label][g]
            out[label][g] = [float(np.sqrt(np.nanmean(residual[:, bins == b] ** 2)) / scatter[label].sd[g][b])
                             if np.any(bins == b) else float("nan") for b in range(len(scatter[label].sd[g]))]
    return out


PHYSICAL = " [physical]"  # a model entry ending so: every index-like parameter's prior held to PTFE_BAND


def entry_parts(entry: str) -> tuple[str, bool, dict]:
    """(model string, whether the indices are held physical, {parameter: fixed value}) of a ``--models`` entry:
    the model, then optionally one bracket of options separated by spaces, ``physical`` and ``NAME=VALUE`` (that
    parameter held at that value: e.g. ``[w_pm=1 dl_pm=0]``, a sub-model whose parameters at a bound are fixed
    there, for ELPD-LOO to weigh against the free one)."""
    spec, _, options = entry.partition(" [")
    physical, fixed = False, {}
    for token in options.removesuffix("]").split():
        name, equals, value = token.partition("=")
        if token == "physical":
            physical = True
        elif not equals:
            raise SpacepolError(f"model entry '{entry}': option '{token}' is neither 'physical' nor NAME=VALUE")
        else:
            try:
                fixed[name] = float(value)
            except ValueError:
                raise SpacepolError(f"model entry '{entry}': '{token}' is not NAME=<number>") from None
    return spec, physical, fixed


def model_for(data, spec: str):
    """The model an entry of ``--models`` names, one index per wavelength where ``data`` hold several."""
    lams = np.unique(data.wavelength_um)
    model = Model.from_string(entry_parts(spec)[0])
    return SpectralModel(model, lams) if len(lams) > 1 else model


def entry_priors(model, spec: str) -> dict:
    """The prior overrides an entry asks for: with ``physical`` every index-like parameter Uniform over PTFE_BAND, so
    that the fit says what holding the indices physical costs; each NAME=VALUE a Fixed prior (a name the model does
    not have is an error)."""
    _, physical, fixed = entry_parts(spec)
    names = [p.name for p in model.parameters]
    unknown = sorted(set(fixed) - set(names))
    if unknown:
        raise SpacepolError(f"model entry '{spec}': no parameter {', '.join(unknown)} in {model.name}")
    out = {p.name: Uniform(*PTFE_BAND) for p in model.parameters if physical and p.name.split("@")[0] in INDEX_LIKE}
    return out | {name: Fixed(value) for name, value in fixed.items()}


def fit(data, spec: str, seed: int, method: str, max_steps: int, noise: dict, scatter: dict,
        search_every: int = 1) -> tuple[dict, object, dict]:
    """(record, Result, standardised residuals) of ``spec`` on ``data``: maximum, posterior, ELPD-LOO, misfit per
    group, indices. ``search_every``: the global search on every n-th row, its optimum polished on all
    (``optimum.find_optimum_on_every``)."""
    start = time.perf_counter()
    model = model_for(data, spec)
    post = Posterior.build(data, model, prior_overrides=entry_priors(model, spec) or None)
    best, centre = find_optimum_on_every(post, search_every, np.random.default_rng(seed), evaluations=3000)
    found = time.perf_counter() - start
    print(f"  {spec}: maximum {best:.1f} in {found:.0f} s; posterior by {method}", flush=True)
    inv, refusal = (laplace_fit(post, centre, seed=seed) if method == "laplace" else (None, "emcee asked for"))
    if inv is None:
        print(f"  {spec}: emcee ({refusal})", flush=True)
        inv = invert(post, seed=seed, progress=False, centre=centre, max_steps=max_steps, max_pointwise_draws=2000)
    s = inv.summary
    parameters = s.parameters | s.derived
    z = standardised(inv, noise)
    record = {
        "model": spec, "free_parameters": post.ndim, "max_log_posterior": best, "engine": s.diagnostics["engine"],
        "laplace_refused": "" if method != "laplace" else refusal, "rhat_max": s.diagnostics["rhat_max"],
        "pareto_k": s.diagnostics.get("pareto_k"), "sd_growth_max": s.diagnostics.get("sd_growth_max"),
        "elpd_loo": s.fit["elpd_loo"], "elpd_loo_se": s.fit["elpd_loo_se"],
        "inferred_noise": {k: v["median"] for k, v in s.parameters.items() if k.startswith("sigma_m_")},
        "noise_factor": noise_factors(data, noise, s.parameters),
        "misfit_ratio": group_ratios(z, data),
        "misfit_by_exit": exit_ratios(z, data, noise, scatter),
        "indices": [{"name": f.name, "median": f.median, "q05": f.q05, "q95": f.q95, "determined": f.determined,
                     "physical": f.physical, "text": f.text} for f in index_findings(parameters, PTFE_BAND)],
        "at_bound": [f"{b['parameter']} at its {b['side']} bound {b['bound']:g}" for b in s.at_bound],
        "seconds": time.perf_counter() - start,
    }
    return record, inv, z


def noise_factors(data, noise: dict, parameters: dict) -> dict | None:
    """{group: the inferred level over ``profile_unit``}, the factor on the noise the measurement shows, where the
    fit had a noise profile (``--noise-profile``); else None."""
    if data.get("mueller_noise_profile") is None:
        return None
    unit = dict(zip(GROUPS, profile_unit(data, noise)))
    return {g: parameters[f"sigma_m_{g}"]["median"] / unit[g] for g in GROUPS if f"sigma_m_{g}" in parameters}


def ranking(records: list[dict], pointwise: dict) -> list[dict]:
    """The models by ELPD-LOO, best first, each difference to the best with the SE of the paired pointwise difference."""
    order = sorted(records, key=lambda r: -r["elpd_loo"])
    top = pointwise[order[0]["model"]]
    out = []
    for r in order:
        d = pointwise[r["model"]] - top
        out.append({"model": r["model"], "elpd_loo": r["elpd_loo"], "elpd_loo_se": r["elpd_loo_se"],
                    "delta_elpd": float(d.sum()), "delta_elpd_se": float(np.sqrt(len(d) * np.var(d)))})
    return out


def standardised(inv, noise: dict) -> dict:
    """{element: (data - posterior-median prediction) / the measured noise of its group at its row's wavelength}."""
    lik, data = inv.posterior.likelihood, inv.posterior.likelihood.data
    mu, _ = median_fit(inv.posterior, inv.draws.flat_samples())
    labels = np.array([wavelength_label(w) for w in data.wavelength_um])
    out = {}
    for ch in lik.observables:
        if ch in GROUP_OF:
            sigma = np.array([noise[label][GROUP_OF[ch]] for label in labels])
            out[ch] = lik.residual(ch, mu[ch]) / sigma
    return out


def group_ratios(z: dict, data) -> dict:
    """{wavelength: {group: RMS of the standardised residuals ``z`` of the rows of ``data``}}: 1 where the model
    leaves the measured noise."""
    out = {}
    for w in np.unique(data.wavelength_um):
        at = data.wavelength_um == w
        out[wavelength_label(w)] = {g: float(np.sqrt(np.nanmean(np.concatenate([z[ch][at] ** 2 for ch in z
                                                                                if GROUP_OF[ch] == g]))))
                                    for g in ("pol", "lin", "circ")}
    return out


def misfit_map(inv, standard: dict):
    """Per wavelength, RMS of the standardised residuals (``standardised``: data - posterior-median prediction over
    the measured noise of each element's group), in bins of theta_i (rows of the data) x theta_r (4 bins): where the
    misfit sits. Element x geometry."""
    lik, data = inv.posterior.likelihood, inv.posterior.likelihood.data
    elements = list(standard)
    incidences = np.unique(np.round(np.abs(data.theta_i)))
    r_edges = np.array([0, 20, 40, 60, 90])
    labels = [wavelength_label(w) for w in np.unique(data.wavelength_um)]
    fig, axes = plt.subplots(len(labels), 1, figsize=(12, 3.1 * len(labels)), constrained_layout=True, squeeze=False)
    maps = {}
    for ax, label in zip(axes[:, 0], labels):
        at = np.isclose(data.wavelength_um, float(label))
        grid = np.full((len(elements), len(incidences) * (len(r_edges) - 1)), np.nan)
        for e, ch in enumerate(elements):
            z = standard[ch]
            for a, ti in enumerate(incidences):
                for b in range(len(r_edges) - 1):
                    rows = at & np.isclose(np.round(np.abs(data.theta_i)), ti) & (np.abs(data.theta_r) >= r_edges[b]) \
                        & (np.abs(data.theta_r) < r_edges[b + 1]) & np.isfinite(z)
                    if rows.any():
                        grid[e, a * (len(r_edges) - 1) + b] = np.sqrt(np.mean(z[rows] ** 2))
        maps[label] = grid
        im = ax.imshow(grid, cmap="magma_r", vmin=0, vmax=4, aspect="auto")
        ax.set_yticks(range(len(elements)), elements, fontsize=7)
        ax.set_xticks(range(grid.shape[1]), [f"{ti:g}|{r_edges[b]}-{r_edges[b + 1]}" for ti in incidences
                                             for b in range(len(r_edges) - 1)], rotation=90, fontsize=6)
        ax.set_title(f"{label} um: RMS residual / measured noise (1 = at the noise)", fontsize=9)
        fig.colorbar(im, ax=ax, pad=0.01)
    axes[-1, 0].set_xlabel("theta_i (deg) | theta_r bin (deg)")
    fig.suptitle(f"Where {lik.model.name} misses PTFE")
    return fig, {"elements": elements, "columns": [f"{ti:g}|{r_edges[b]}-{r_edges[b + 1]}" for ti in incidences
                                                   for b in range(len(r_edges) - 1)],
                 "rms": {k: v.tolist() for k, v in maps.items()}}


def top_findings(records: list[dict]) -> list[str]:
    """What the report says first: the indices of the best model, and whether any group exceeds the goal."""
    best = max(records, key=lambda r: r["elpd_loo"])
    out = []
    bad = [i for i in best["indices"] if i["physical"] is False]
    if bad:
        out.append(f"The best model by ELPD-LOO ({best['model']}) puts " + "; ".join(i["text"] for i in bad)
                   + f". Porous PTFE's effective index lies in [{PTFE_BAND[0]}, {PTFE_BAND[1]}] (grains 1.35): this model "
                   "cannot reach the physical value; its index absorbs a misfit.")
    open_ = [i["name"] for i in best["indices"] if not i["determined"]]
    if open_:
        out.append(f"Not determined by the data under {best['model']}: {', '.join(open_)} (90 % interval >= 0.3).")
    good = [i["text"] for i in best["indices"] if i["physical"]]
    if good:
        out.append("Determined and physical: " + "; ".join(good) + ".")
    held = {r["model"].removesuffix(PHYSICAL): r for r in records if r["model"].endswith(PHYSICAL)}
    for r in records:
        if r["model"] in held:
            h = held[r["model"]]
            out.append(f"Held to the physical band [{PTFE_BAND[0]}, {PTFE_BAND[1]}], the indices of {r['model']} cost "
                       f"{r['max_log_posterior'] - h['max_log_posterior']:.0f} log units of the maximum posterior "
                       f"(ELPD-LOO {h['elpd_loo'] - r['elpd_loo']:.0f}) and raise the misfit to "
                       + ", ".join(f"{g}@{w} {v:.2f}" for w, groups in h["misfit_ratio"].items() for g, v in groups.items())
                       + "; they go to " + ", ".join(f"{i['name']} {i['median']:.3f}" for i in h["indices"])
                       + " (the band's edge): the data themselves, not the prior, push the indices out of the band. "
                       + risen_most(r, h))
    if best.get("noise_factor"):
        factors = best["noise_factor"]
        over = [g for g, v in factors.items() if v > GOAL_RATIO]
        out.append(f"Inferred noise of {best['model']} over the noise the measurement shows (`--noise-profile`: the "
                   "reciprocal pairs' at each wavelength, the mirror pairs' rise with the exit angle), one factor per "
                   "group: " + ", ".join(f"{g} {v:.2f}" for g, v in factors.items())
                   + (f": {', '.join(over)} above {GOAL_RATIO}." if over else f": every group within {GOAL_RATIO}x."))
    ratios = {f"{g}@{w}": v for w, groups in best["misfit_ratio"].items() for g, v in groups.items()}
    above = [k for k, v in ratios.items() if v > GOAL_RATIO]
    out.append(f"Misfit of {best['model']} = RMS residual / the measured noise, per element group and wavelength: "
               + ", ".join(f"{k} {v:.2f}" for k, v in ratios.items())
               + (f": {', '.join(above)} above {GOAL_RATIO}, so the model is not yet at the data's noise there."
                  if above else f": every group within {GOAL_RATIO}x of the measured noise."))
    for r in records:
        if r["model"] == "paper":
            n = [i for i in r["indices"] if i["name"].split("@")[0] == "n"]
            if n:
                out.append("The paper's model gives " + "; ".join(f"{i['name']} {i['median']:.3f}" for i in n)
                           + ": that model's failure (a specular lobe that must carry the body's polarization), not a "
                           "measurement of PTFE's index.")
    return out


GROUP_WORDS = {"pol": "the polarizance and diattenuation elements (m12 m13 m14 m21 m31 m41)",
               "lin": "the linear block (m22 m23 m32 m33)", "circ": "the circular elements (m24 m34 m42 m43 m44)"}


def risen_most(free: dict, held: dict) -> str:
    """Which element group's misfit rises most when the indices are held physical, and what that says."""
    rise = {g: np.mean([held["misfit_ratio"][w][g] - free["misfit_ratio"][w][g] for w in free["misfit_ratio"]])
            for g in GROUP_WORDS}
    group = max(rise, key=rise.get)
    text = f"The misfit rises most in {GROUP_WORDS[group]} (+{rise[group]:.2f}x the measured noise on average)"
    if group == "pol":
        text += (": the flat interfaces of index >= 1.15 that the model's light crosses polarize it (Fresnel "
                 "transmission's diattenuation) more than PTFE's porous surface does, so the fit flattens them to n ~ 1")
    return text + "."


def misfit_words(misfit: dict) -> str:
    """Where the best model's misfit sits, from ``misfit_map``'s record: the elements whose RMS residual exceeds twice
    the measured noise in most geometry bins, at each wavelength."""
    parts = []
    for label, grid in misfit["rms"].items():
        grid = np.array(grid, float)
        worst = [(e, float(np.nanmedian(row))) for e, row in zip(misfit["elements"], grid) if np.nanmedian(row) > 2]
        parts.append(f"{label} um: " + (", ".join(f"{e} {v:.1f}x" for e, v in worst) or "no element above 2x"))
    return ("Where the best model misses (median over the theta_i x theta_r bins of misfit.png of the RMS residual / "
            "measured noise, elements above 2x): " + "; ".join(parts))


def posterior_words(record: dict) -> str:
    """How the posterior was drawn, and NOT converged where an emcee chain stopped at its cap above R-hat 1.01."""
    if record["engine"] != "emcee" or record["rhat_max"] is None or record["rhat_max"] <= 1.01:
        return record["engine"]
    return f"emcee, NOT converged (R-hat {record['rhat_max']:.2f}): its ELPD-LOO is not to be trusted"


def exit_lines(scatter: dict, noise: dict, records: list[dict]) -> list[str]:
    """The report's section on the measurement's spread by exit angle, and the best model's misfit against it."""
    labels = next(iter(scatter.values())).labels()
    lines = ["", "## The measurement's own spread by exit angle (mirror pairs)", "",
             "The reciprocal pairs lie at theta 30 and 45 deg only. The mirror pairs (dphi, -dphi) cover every exit "
             "angle: the robust SD of one normalised element from their differences, an upper bound of the noise "
             "(anisotropy adds to it), against the reciprocal pairs' noise:", "",
             "| wavelength | group | reciprocal pairs | " + " | ".join(labels) + " |", "|---|---|---|" + "---|" * len(labels)]
    for w, sc in scatter.items():
        for g in ("pol", "lin", "circ"):
            lines.append(f"| {w} | {g} | {noise.get(w, {}).get(g, float('nan')):.4f} | "
                         + " | ".join(f"{v:.4f}" for v in sc.sd[g]) + " |")
    fitted = [r for r in records if "misfit_by_exit" in r]
    if fitted:
        best = max(fitted, key=lambda r: r["elpd_loo"])
        lines += ["", f"{best['model']}'s RMS residual over that spread, per exit-angle bin (1: the model leaves what "
                  f"the data scatter by; goal <= {GOAL_RATIO}):", "",
                  "| wavelength | group | " + " | ".join(labels) + " |", "|---|---|" + "---|" * len(labels)]
        for w, groups in best["misfit_by_exit"].items():
            for g, values in groups.items():
                lines.append(f"| {w} | {g} | " + " | ".join(f"{v:.2f}" for v in values) + " |")
    return lines


def write_report(out: Path, args, data, noise, scatter, aniso, masked: int, records, table, misfit) -> None:
    lines = [f"# PTFE under competing models ({', '.join(sorted(noise))} um jointly)", "",
             f"Re-made by `python studies/ptfe_models.py {' '.join(sys.argv[1:])}`; {len(data)} geometries"
             + (f" after {masked} anisotropic rows left out" if masked else "") + ".", "", "## Findings", ""]
    lines += [f"- {f}" for f in (top_findings(records) if records else ["no model fitted yet"])]
    if misfit:
        lines.append(f"- {misfit_words(misfit)}")
    lines += ["", "## The noise the data measure (reciprocal pairs)", "", "| wavelength | pol | lin | circ |", "|---|---|---|---|"]
    lines += [f"| {w} | " + " | ".join(f"{v.get(g, float('nan')):.4f}" for g in ("pol", "lin", "circ")) + " |"
              for w, v in noise.items()]
    lines += exit_lines(scatter, noise, records)
    lines += ["", "## Anisotropy, from the data alone", ""]
    lines += [f"- {w} um: {a.text}" for w, (a, _) in aniso.items()]
    lines += ["", ("The rows of the flagged pairs are left out of the fits (`--mask-anisotropic`)." if masked else
                   "Every row is fitted (no `--mask-anisotropic`): an isotropic model cannot fit the flagged pairs' "
                   "asymmetry, and it stays in their residuals.")]
    lines += ["", "## Models ranked by ELPD-LOO", "",
              "| model | free parameters | ELPD-LOO | delta ELPD vs best | posterior | misfit (RMS residual / measured noise) | indices | s |",
              "|---|---|---|---|---|---|---|---|"]
    by_model = {r["model"]: r for r in records}
    for t in table:
        r = by_model[t["model"]]
        lines.append(f"| {t['model']} | {r['free_parameters']} | {t['elpd_loo']:.1f} +- {t['elpd_loo_se']:.1f} | "
                     f"{t['delta_elpd']:.1f} +- {t['delta_elpd_se']:.1f} | {posterior_words(r)} | "
                     + ", ".join(f"{g}@{w} {v:.2f}" for w, groups in r["misfit_ratio"].items() for g, v in groups.items())
                     + " | "
                     + ", ".join(f"{i['name']} {i['median']:.3f} [{i['q05']:.3f}, {i['q95']:.3f}]" for i in r["indices"])
                     + f" | {r['seconds']:.0f} |")
    if misfit:
        lines += ["", "![misfit](misfit.png)"]
    write_text(out / "report.md", "\n".join(lines) + "\n")


def pointwise_file(out: Path, spec: str) -> Path:
    """Where a model's pointwise ELPD-LOO is kept (the ranking's paired differences need it)."""
    name = spec.replace(PHYSICAL, "_physical").replace("+", "_")
    return out / "pointwise" / f"{re.sub(r'[^A-Za-z0-9_.-]', '_', name)}.npy"


def finished(out: Path, settings: dict) -> tuple[dict, dict | None, str | None]:
    """What an earlier run of the same settings in ``out`` measured: ({model: record} for the models whose pointwise
    ELPD-LOO was kept, the misfit map's record, the model it maps); nothing where the settings differ."""
    try:
        old = json.loads((out / "study.json").read_text())
    except (OSError, ValueError):
        return {}, None, None
    if old.get("settings") != settings:
        return {}, None, None
    done = {r["model"]: r for r in old.get("records", []) if pointwise_file(out, r["model"]).is_file()}
    return done, old.get("misfit"), old.get("misfit_model")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--wavelength-um", default="all")
    parser.add_argument("--in-plane", action="store_true")
    parser.add_argument("--mask-anisotropic", action="store_true")
    parser.add_argument("--noise-profile", action="store_true", help="each row's noise as the measurement shows it "
                        "(reciprocal pairs per wavelength, mirror pairs per exit angle), times one inferred factor "
                        "per element group")
    parser.add_argument("--models", default=MODELS)
    parser.add_argument("--posterior", choices=("laplace", "emcee"), default="laplace")
    parser.add_argument("--max-steps", type=int, default=4000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--search-every", type=int, default=1, help="the global search of each model's maximum on "
                        "every n-th row only, then polished on all rows (8 for the whole file at four wavelengths)")
    parser.add_argument("--out", default="reports/ptfe_models")
    args = parser.parse_args(argv)
    from spacepol import configure_process

    configure_process(small_calls=True)  # the settings the command line makes, its compiled programs kept on disk
    data = load(args.wavelength_um)
    try:  # every model named, with its options, before any work
        for spec in args.models.split(","):
            entry_priors(model_for(data, spec), spec)
    except SpacepolError as error:
        print(f"ptfe_models: --models: {error}", file=sys.stderr)
        return 2
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    noise = measured_noise(data)  # from every row: the plane of incidence alone holds no reciprocal pair
    aniso = anisotropy(data, noise)
    scatter = exit_scatter(data)  # from every row, before any is left out: a mirror pair needs both members
    if args.noise_profile:  # from every row, before any is left out (as the spread it rests on)
        data.mueller_noise_profile = measured_noise_profile(data, noise)
    masked = 0
    if args.mask_anisotropic:
        drop = np.unique(np.concatenate([rows for _, rows in aniso.values()] or [np.empty(0, int)]))
        data, masked = data.select(np.setdiff1d(np.arange(len(data)), drop)), len(drop)
    if args.in_plane:
        data = data.in_plane()
    print(f"PTFE: {len(data)} geometries ({masked} anisotropic rows left out); {os.cpu_count()} cores, "
          f"load {os.getloadavg()[0]:.2f}", flush=True)
    settings = {k: getattr(args, k) for k in ("wavelength_um", "in_plane", "mask_anisotropic", "noise_profile", "posterior",
                                              "max_steps", "seed", "search_every")}
    done, misfit, misfit_model = finished(out, settings)
    records, pointwise = [], {}
    for spec in args.models.split(","):
        if spec in done:  # the same command ran this model before: its record and pointwise ELPD are kept
            record, inv, standard = done[spec], None, None
            pointwise[spec] = np.load(pointwise_file(out, spec))
            print(f"  {spec}: kept from {out / 'study.json'} (ELPD-LOO {record['elpd_loo']:.1f})", flush=True)
        else:
            record, inv, standard = fit(data, spec, args.seed, args.posterior, args.max_steps, noise, scatter,
                                        args.search_every)
            pointwise[spec] = np.asarray(inv.loo["pointwise"])
            pointwise_file(out, spec).parent.mkdir(exist_ok=True)
            np.save(pointwise_file(out, spec), pointwise[spec])
        records.append(record)
        table = ranking(records, pointwise)
        if table[0]["model"] == spec and inv is not None:
            fig, misfit = misfit_map(inv, standard)
            misfit_model = spec
            save_figure(fig, out / "misfit.png")
        elif table[0]["model"] != misfit_model:
            misfit = None  # the best model was kept from an earlier run that did not map its misfit
        write_json(out / "study.json", {"settings": settings, "records": records, "ranking": table,
                                        "measured_noise": noise,
                                        "mirror_spread": {w: {"edges_deg": sc.edges_deg, **{g: sc.sd[g].tolist()
                                                                                             for g in sc.sd}}
                                                          for w, sc in scatter.items()},
                                        "anisotropy": {w: {"pairs": len(a.pairs), "flagged": int(a.flagged.sum()),
                                                           "chi2_per_dof": a.excess} for w, (a, _) in aniso.items()},
                                        "masked_rows": masked, "misfit": misfit, "misfit_model": misfit_model})
        write_report(out, args, data, noise, scatter, aniso, masked, records, table, misfit)
        print(f"  {spec}: ELPD-LOO {record['elpd_loo']:.1f} +- {record['elpd_loo_se']:.1f} ({record['engine']}, "
              f"{record['seconds']:.0f} s)", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
