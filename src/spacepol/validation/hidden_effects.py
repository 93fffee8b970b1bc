"""Validation of `diagnose` on data with a hidden effect (and on null sets without one).

Each case draws a synthetic measurement from ``paper + E`` (E a built-in effect at a chosen
value), with a given noise level and angle sampling, runs :func:`diagnose` with the whole
library, and scores: was E named (or reported as a twin of the verdict)?  does adding E bring
the reduced chi^2 to the noise floor and recover E's own parameter in its 90 % interval?

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from matplotlib.figure import Figure

from ..infer.engines.de import run_de
from ..infer.inference_data import standardised_residuals
from ..infer.objective import NegativeLogPosterior
from ..infer.posterior import Posterior
from ..io.measurements import Dataset
from ..physics.geometry import Geometry, default_grid
from ..physics.model import Model
from ..physics.registry import BUILTIN_EFFECTS, registry
from ..criticism.diagnose import diagnose
from ..criticism.explain import posterior_quality

BASE = "paper"
MATERIALS = {  # two base materials the cases alternate between
    "paint": {"n": 1.5, "k": 0.0, "sigma": 0.25, "ks": 0.6, "rho_d": 0.3},
    "oxidised metal": {"n": 1.8, "k": 1.2, "sigma": 0.15, "ks": 0.8, "rho_d": 0.1},
}
# per built-in effect that composes with the base: its own small and large value (``Effect.hidden_values``)
HIDDEN_VALUES = {cls.name: list(cls.hidden_values) for cls in BUILTIN_EFFECTS if cls.hidden_values}
NOISE = [(0.002, 0.01), (0.01, 0.05)]  # (DOP absolute, BRDF relative): a good lab polarimeter, a field one
WAVELENGTH_UM = 0.633


def sampling(name: str) -> Geometry:
    """The angle samplings the suite uses (all at 0.633 um, so thin films are defined)."""
    if name == "in-plane-84":
        g = default_grid()
    elif name == "two-sided-out-of-plane-72":
        # theta_i 30 and 60 deg; theta_r 10-70 deg; dphi 180 (forward), 135, 90 and 0 (back)
        ti = np.repeat([30.0, 60.0], 36)
        tr = np.tile(np.repeat(np.arange(10.0, 71.0, 7.5)[:9], 4), 2)
        dphi = np.tile([180.0, 135.0, 90.0, 0.0], 18)
        g = Geometry(ti, tr, dphi)
    else:
        raise ValueError(f"unknown sampling '{name}'")
    return Geometry(g.theta_i, g.theta_r, g.dphi, np.full(g.size, WAVELENGTH_UM))


@dataclass
class Case:
    """One validation set: the hidden effect (None: a null set) and its values, material, noise, sampling and seed."""
    label: str
    effect: str | None  # None: a null set
    hidden: dict
    material: str
    noise_dop: float
    noise_brdf: float
    sampling: str
    seed: int
    size: float = field(default=np.nan)

    @property
    def spec(self) -> str:
        """The model that renders the case: the base model plus the hidden effect."""
        return BASE if self.effect is None else f"{BASE}+{self.effect}"

    @property
    def truth(self) -> dict:
        """Every parameter's true value: the model's defaults, the material's and the hidden effect's values."""
        model = Model.from_string(self.spec)
        names = {p.name for p in model.parameters}
        return {**model.defaults(), **{k: v for k, v in MATERIALS[self.material].items() if k in names}, **self.hidden}


def suite(effects=None, n_null: int = 8, seed: int = 0) -> list[Case]:
    """Every effect x value x noise level, samplings and materials alternating; plus null sets. ``effects``: those
    effects' cases only, each the same case (material, sampling, seed) as in the whole suite."""
    unknown = sorted(set(effects or ()) - set(HIDDEN_VALUES))
    if unknown:
        raise ValueError(f"effects {', '.join(unknown)}: not among the suite's ({', '.join(HIDDEN_VALUES)})")
    cases = []
    for k, effect in enumerate(HIDDEN_VALUES):  # k: the effect's place in the whole suite, whatever is asked for
        if effects and effect not in effects:
            continue
        for v, hidden in enumerate(HIDDEN_VALUES[effect]):
            for j, (nd, nb) in enumerate(NOISE):
                samp = ["in-plane-84", "two-sided-out-of-plane-72"][(v + j) % 2]
                mat = list(MATERIALS)[(v + j + k) % 2]
                cases.append(Case(f"{effect}#{v}/{nd}", effect, hidden, mat, nd, nb, samp, seed + 1000 * k + 10 * v + j))
    for i in range(n_null):
        nd, nb = NOISE[i % 2]
        cases.append(Case(f"null#{i}", None, {}, list(MATERIALS)[(i // 2) % 2], nd, nb,
                          ["in-plane-84", "two-sided-out-of-plane-72"][(i // 4) % 2], seed + 90000 + i))
    return cases


def measurement(case: Case, noisy: bool = True) -> Dataset:
    """The case's data set: its model's DOP and BRDF at the case's sampling, with the case's noise unless ``noisy`` is
    False."""
    g = sampling(case.sampling)
    pred = Model.from_string(case.spec).evaluate(case.truth, g)
    rng = np.random.default_rng(case.seed)
    eps_dop, eps_brdf = (rng.standard_normal(g.size), rng.standard_normal(g.size)) if noisy else (0.0, 0.0)
    data = Dataset(g.theta_i, g.theta_r, g.dphi, wavelength_um=g.wavelength_um)
    data.dop = np.clip(pred.dop + case.noise_dop * eps_dop, 0.0, 1.0)
    data.dop_err = np.full(g.size, case.noise_dop)
    data.brdf = np.maximum(pred.brdf * (1.0 + case.noise_brdf * eps_brdf), 0.0)
    data.brdf_err = case.noise_brdf * pred.brdf
    return data


def effect_size(case: Case, rng: np.random.Generator, evaluations: int = 6000) -> float:
    """RMS residual / noise of the base model's best fit to the noise-free data (see module doc)."""
    posterior = Posterior.build(measurement(case, noisy=False), Model.from_string(BASE))
    best = run_de(NegativeLogPosterior(posterior), rng, max_evaluations=evaluations, popsize=10, polish=True)
    z = standardised_residuals(posterior, best.best_vector()[None, :])
    return float(np.sqrt(np.mean(np.concatenate(list(z.values())) ** 2)))


def identifiable(effect: str, names: list[str], samples: np.ndarray, truth: dict) -> tuple[np.ndarray, dict]:
    """Samples and truth in the form the data can identify, as the effect itself declares it
    (``Effect.identifiable``: e.g. anisotropy's label swaps)."""
    canonical = registry.get(effect)().identifiable
    values = canonical({n: samples[:, j] for j, n in enumerate(names)})
    out = np.column_stack([np.asarray(values[n], float) for n in names])
    t = canonical({k: np.float64(v) for k, v in truth.items()})
    return out, {k: float(t[k]) for k in truth}


def covered(effect: str, inversion, truth: dict) -> dict[str, bool]:
    """Is each hidden parameter inside the 5-95 % interval of its (identifiable) marginal?"""
    names = inversion.draws.names
    samples, truth = identifiable(effect, names, inversion.draws.flat_samples(), truth)
    out = {}
    for name, value in truth.items():
        lo, hi = np.percentile(samples[:, names.index(name)], [5, 95])
        out[name] = bool(lo <= value <= hi)
    return out


def score(case: Case, report: dict) -> dict:
    """One row of the validation table: the verdict, whether it named the hidden effect (or none for a null case), and
    the fit after the change."""
    lead = report["ranking"][0] if report["ranking"] else {}
    named = [report["verdict"]] + lead.get("tied_with", [])
    out = {"label": case.label, "effect": case.effect or "none", "material": case.material, "sampling": case.sampling,
           "noise_dop": case.noise_dop, "size": case.size, "verdict": report["verdict"], "tied_with": lead.get("tied_with", []),
           "correct": (report["verdict"] == "none") if case.effect is None else (case.effect in named),
           "chi2_red_base": report["fit"]["chi2_red"]}
    confirmed = {c.effect: c for c in report.confirmed if c.kind == "add"}
    if case.effect in confirmed:
        inversion = confirmed[case.effect].inversion
        out["chi2_red_after"] = inversion.summary.fit["chi2_red"]
        out["covered"] = covered(case.effect, inversion, case.hidden)
        # the intervals come from diagnose's refit: emcee stopped where its ELPD-LOO settled is no converged posterior
        out["refit"] = {k: v for k, v in posterior_quality(inversion).items() if k != "laplace_refused"}
    return out


def run_case(case: Case, seed: int = 0, progress: bool = False) -> dict:
    """Render the case, diagnose it from the base model and score the verdict."""
    rng = np.random.default_rng(case.seed)
    if case.effect is not None:
        case.size = effect_size(case, rng)
    report = diagnose(measurement(case), Model.from_string(BASE), rng, seed=seed, progress=progress)
    return score(case, report)


def summarise(rows: list[dict], threshold: float = 3.0) -> dict:
    """The suite's figures: how often the hidden effect is named (all cases and those above ``threshold`` in size),
    false alarms on null cases, interval coverage after the change (and that of the refits that did not converge)."""
    hidden = [r for r in rows if r["effect"] != "none"]
    big = [r for r in hidden if r["size"] >= threshold]
    nulls = [r for r in rows if r["effect"] == "none"]
    after = [r for r in big if "chi2_red_after" in r]
    covered = [ok for r in after for ok in r["covered"].values()]
    unconverged = [ok for r in after if not r.get("refit", {}).get("converged", True) for ok in r["covered"].values()]
    return {
        "threshold_size": threshold,
        "n_hidden_big": len(big), "named_rate_big": float(np.mean([r["correct"] for r in big])) if big else None,
        "n_hidden_small": len(hidden) - len(big),
        "named_rate_small": float(np.mean([r["correct"] for r in hidden if r["size"] < threshold])) if len(hidden) > len(big) else None,
        "n_null": len(nulls), "none_rate_null": float(np.mean([r["correct"] for r in nulls])) if nulls else None,
        "n_after": len(after),
        "chi2_within_1p5": float(np.mean([abs(r["chi2_red_after"] - 1) <= 1.5 for r in after])) if after else None,
        "n_parameters_checked": len(covered), "coverage_90": float(np.mean(covered)) if covered else None,
        # of those, read from refits that did not converge (their misses are the sampler's as much as the model's)
        "n_parameters_unconverged": len(unconverged),
        "coverage_90_unconverged": float(np.mean(unconverged)) if unconverged else None,
    }


def detection_figure(rows: list[dict], threshold: float = 3.0, fig=None, ax=None) -> Figure:
    """Named (1) or not (0) against effect size / noise, one marker per effect; nulls at the left."""
    fig = ax.figure if ax is not None else (fig or Figure(figsize=(7.5, 4.0), layout="constrained"))
    ax = ax or fig.add_subplot()
    effects = sorted({r["effect"] for r in rows if r["effect"] != "none"})
    for i, effect in enumerate(effects):
        sel = [r for r in rows if r["effect"] == effect]
        jitter = 0.04 * (i - len(effects) / 2)
        ax.scatter([max(r["size"], 1e-2) for r in sel], [float(r["correct"]) + jitter for r in sel], label=effect,
                   marker="os^vD<>p*"[i % 9])
    nulls = [r for r in rows if r["effect"] == "none"]
    if nulls:
        ax.scatter([5e-3] * len(nulls), [float(r["correct"]) for r in nulls], c="k", marker="x", label="null (correct = 'none')")
    ax.axvline(threshold, color="k", ls=":", lw=0.8)
    ax.set_xscale("log")
    ax.set_yticks([0, 1], ["missed / wrong", "named"])
    ax.set_xlabel("effect size: RMS misfit of the best paper-model fit / noise")
    ax.legend(fontsize=7, ncol=2, loc="center right")
    ax.set_title("diagnose on data with a hidden effect", fontsize=9)
    return fig


def _run_indexed(args):
    i, case, seed = args
    return i, run_case(case, seed=seed)


def run_suite(cases: list[Case], seed: int = 0, jobs: int = 1, progress: bool = True) -> list[dict]:
    """Run every case (in ``jobs`` processes); rows come back in the order of ``cases``."""
    rows = [None] * len(cases)
    tasks = [(i, c, seed) for i, c in enumerate(cases)]
    if jobs > 1:
        from .._runtime import spawned_pool

        with spawned_pool(jobs) as pool:
            done = pool.map(_run_indexed, tasks)
            for k, (i, row) in enumerate(done):
                rows[i] = row
                if progress:
                    _print_row(k, len(cases), row)
    else:
        for k, task in enumerate(tasks):
            i, row = _run_indexed(task)
            rows[i] = row
            if progress:
                _print_row(k, len(cases), row)
    return rows


def _print_row(k, n, row):
    size = "  null" if row["effect"] == "none" else f"{row['size']:6.2f}"
    after = f" chi2_red after {row['chi2_red_after']:.2f}, covered {row['covered']}" if "chi2_red_after" in row else ""
    print(f"[{k + 1}/{n}] {row['label']:<26s} size {size}  verdict {row['verdict']:<18s} "
          f"{'ok' if row['correct'] else 'WRONG'}{after}", flush=True)
