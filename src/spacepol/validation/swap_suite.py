"""Validation of diagnose --rounds where the paper's model is wrong in parts.

Data come from ``specular+smith+lambertian`` (reciprocal, physical shadowing and diffuse terms) plus
one hidden effect E, or none; diagnose starts from ``paper`` (empirical shadowing, non-reciprocal
body) with ``rounds`` rounds.  A case is right when the path holds the shadowing swap, the body swap
(or an equivalent diffuse change) and E (or a declared/tied twin), with no addition on the null
sets, and the final residuals look like noise (reduced chi^2 < 1.5 with the known noise).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib.figure import Figure

from ..io.measurements import Dataset
from ..physics.model import Model
from ..physics.registry import registry
from .hidden_effects import HIDDEN_VALUES, NOISE, WAVELENGTH_UM, sampling
from ..criticism.rounds import diagnose_rounds

SWAP_BASE = "specular+smith+lambertian"
START = "paper"
MATERIALS = {
    "paint": {"n": 1.5, "k": 0.0, "sigma": 0.25, "ks": 0.6, "rho_l": 0.3},
    "oxidised metal": {"n": 1.8, "k": 1.2, "sigma": 0.15, "ks": 0.8, "rho_l": 0.1},
}
EFFECTS = [None, "dop_bias", "angle_offset", "extinction", "polarized_diffuse", "ggx"]
DIFFUSE_CHANGES = ("replace body by lambertian", "replace body by polarized_diffuse", "add lambertian")


@dataclass
class SwapCase:
    """One set of the swap suite: the effect hidden in the swap base (None: the base alone), material, noise,
    sampling, seed."""
    label: str
    effect: str | None
    material: str
    noise: tuple
    sampling: str
    seed: int

    @property
    def spec(self) -> str:
        """The model that renders the case: the swap suite's base plus the hidden effect."""
        return SWAP_BASE if self.effect is None else f"{SWAP_BASE}+{self.effect}"

    @property
    def hidden(self) -> dict:
        """The hidden effect's own parameter values (empty for a null case)."""
        return {} if self.effect is None else dict(HIDDEN_VALUES[self.effect][1])

    @property
    def truth(self) -> dict:
        """Every parameter's true value: the model's defaults, the material's and the hidden effect's values."""
        model = Model.from_string(self.spec)
        names = {p.name for p in model.parameters}
        return {**model.defaults(), **{k: v for k, v in MATERIALS[self.material].items() if k in names}, **self.hidden}


def swap_suite(seed: int = 0) -> list[SwapCase]:
    """The suite's cases: every hidden effect (and none) twice, materials, noise levels and samplings alternating,
    seeds from ``seed``."""
    cases = []
    for i, effect in enumerate(EFFECTS):
        for j in range(2):
            cases.append(SwapCase(f"swap+{effect or 'none'}#{j}", effect, list(MATERIALS)[(i + j) % 2], NOISE[j],
                                  ["in-plane-84", "two-sided-out-of-plane-72"][(i + j) % 2], seed + 7000 + 10 * i + j))
    return cases


def measurement(case: SwapCase) -> Dataset:
    """The case's data set: DOP and BRDF of its model at its sampling with its noise."""
    g = sampling(case.sampling)
    pred = Model.from_string(case.spec).evaluate(case.truth, g)
    rng = np.random.default_rng(case.seed)
    noise_dop, noise_brdf = case.noise
    data = Dataset(g.theta_i, g.theta_r, g.dphi, wavelength_um=np.full(g.size, WAVELENGTH_UM))
    data.dop = np.clip(pred.dop + noise_dop * rng.standard_normal(g.size), 0.0, 1.0)
    data.dop_err = np.full(g.size, noise_dop)
    data.brdf = np.maximum(pred.brdf * (1.0 + noise_brdf * rng.standard_normal(g.size)), 0.0)
    data.brdf_err = noise_brdf * pred.brdf
    return data


def shadowing_swapped(rounds: list[dict], final_model: str) -> bool:
    """The path put Smith's shadowing in place of the paper's: the final model holds smith (swapped in one
    round, or removed and added back), or a shadowing-slot change was tied with the swap, or the data
    cannot tell the final model's shadowing slot from smith (an equivalent where the path stopped)."""
    final = final_model.split("+")
    if "smith" in final and "shadowing" not in final:
        return True
    if any("shadowing" in (r["change"] or "") and "replace shadowing by smith" in r.get("tied_with", []) for r in rounds):
        return True
    return "smith" not in final and any(e["change"].endswith(" smith") for e in rounds[-1].get("equivalent", []))


def score(case: SwapCase, result: dict) -> dict:
    """One row of the swap suite's table: the path diagnose took, whether it found the hidden effect (or added nothing
    for a null case), and the final fit."""
    path = [r["change"] for r in result["rounds"][1:]]
    final = result["rounds"][-1]
    tied = {t for report in result.reports for entry in report["ranking"][:1] for t in entry.get("tied_with", [])}
    additions = [c for c in path if c.startswith("add ") and c not in DIFFUSE_CHANGES]
    if case.effect is None:  # no addition of an effect the surface does not have (smith refilling its slot is fine)
        effect_ok = not [a for a in additions if a.split()[1] not in case.spec.split("+")]
    else:
        twins = set(registry.get(case.effect).twins)  # declared twins count, as tied ones do
        effect_ok = f"add {case.effect}" in path or any(a.split()[1] in tied | twins for a in additions) or \
            any(case.effect in c or any(t in c for t in twins) for c in path)
    return {"label": case.label, "effect": case.effect or "none", "material": case.material, "sampling": case.sampling,
            "noise_dop": case.noise[0], "path": path, "final_model": result["final_model"],
            "chi2_red_final": final["fit"]["chi2_red"],
            "chi2_red_per_round": [r["fit"]["chi2_red"] for r in result["rounds"]],
            "shadowing_swap": shadowing_swapped(result["rounds"], result["final_model"]),
            "equivalent": [e["change"] for e in result["rounds"][-1].get("equivalent", [])],
            "diffuse_change": any(c in DIFFUSE_CHANGES for c in path), "effect_ok": bool(effect_ok),
            "noise_like": final["fit"]["chi2_red"] < 1.5,
            "correct": bool(shadowing_swapped(result["rounds"], result["final_model"]) and effect_ok
                            and final["fit"]["chi2_red"] < 1.5)}


def summarise_swaps(rows: list[dict]) -> dict:
    """Rates over the swap cases: right path and noise-like end; no spurious addition on the nulls."""
    nulls = [r for r in rows if r["effect"] == "none"]
    return {"n_swap": len(rows), "swap_correct_rate": float(np.mean([r["correct"] for r in rows])) if rows else None,
            "swap_noise_like_rate": float(np.mean([r["noise_like"] for r in rows])) if rows else None,
            "swap_shadowing_swap_rate": float(np.mean([r["shadowing_swap"] for r in rows])) if rows else None,
            "n_swap_null": len(nulls), "swap_null_clean_rate": float(np.mean([r["effect_ok"] for r in nulls])) if nulls else None}


def swap_figure(rows: list[dict], ax=None) -> Figure:
    """Reduced chi^2 per round along each swap case's path (log scale): the error falls round by round
    to the noise level (1) where the path is right."""
    fig = ax.figure if ax is not None else Figure(figsize=(6.0, 4.0), layout="constrained")
    ax = ax or fig.add_subplot()
    effects = sorted({r["effect"] for r in rows})
    for r in rows:
        i = effects.index(r["effect"])
        chi2 = r["chi2_red_per_round"]
        ax.plot(range(len(chi2)), chi2, marker="os^vD<>p*"[i % 9], color=f"C{i}", ls="-" if r["correct"] else ":",
                lw=1.0, label=r["effect"] if r is next(x for x in rows if x["effect"] == r["effect"]) else None)
    ax.axhline(1.0, color="k", lw=0.6)
    ax.axhline(1.5, color="k", ls=":", lw=0.8)
    ax.set_yscale("log")
    ax.set_xticks(range(max((len(r["chi2_red_per_round"]) for r in rows), default=1)))
    ax.set_xlabel("round (0 = the paper's model)")
    ax.set_ylabel("reduced chi^2 (known noise)")
    ax.legend(fontsize=7, title="hidden effect (dotted: wrong path)", title_fontsize=7)
    ax.set_title("diagnose --rounds from paper on specular+smith+lambertian+E", fontsize=9)
    return fig


def run_swap_case(case: SwapCase, rounds: int = 4, seed: int = 0, progress: bool = False) -> dict:
    """Render the case and run ``diagnose --rounds`` from the paper's wrong model; the scored row."""
    rng = np.random.default_rng(case.seed)
    result = diagnose_rounds(measurement(case), Model.from_string(START), rng, rounds, seed=seed, progress=progress)
    return score(case, result)
