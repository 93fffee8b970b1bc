"""The paper's Table 1 experiment, honestly, on synthetic data.

DOP against incidence angle in the specular geometry (theta_r = theta_i, dphi = 180 deg, as in
the paper's Figure 2) for aluminium (n = 1.24, k = 6.6) and black paint (n = 1.405, k = 0.2289),
generated with the corrected `paper` model and Gaussian DOP noise of 0.01. Each set is inverted
with the paper's GA (its settings) and with emcee. Writes reports/table1/.

    python examples/table1_experiment.py [--out reports/table1] [--seed 0]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from spacepol.infer.engine_registry import optimize
from spacepol.infer.inversion import invert
from spacepol.infer.objective import PaperObjective
from spacepol.infer.posterior import Posterior
from spacepol.infer.prior_set import PriorSet
from spacepol.io.atomic import save_figure, write_json
from spacepol.io.measurements import Dataset
from spacepol.physics import Geometry, Model

MATERIALS = {
    "aluminium": {"n": 1.24, "k": 6.6, "sigma": 0.15, "ks": 0.8, "rho_d": 0.05},
    "black paint": {"n": 1.405, "k": 0.2289, "sigma": 0.25, "ks": 0.3, "rho_d": 0.2},
}
PAPER_ESTIMATES = {"aluminium": (1.231, 6.574), "black paint": (1.429, 0.2398)}
NOISE = 0.01
ANGLES = np.arange(10.0, 81.0, 5.0)


def make_data(truth, rng):
    data = Dataset(ANGLES.copy(), ANGLES.copy(), np.full(ANGLES.size, 180.0))
    dop = Model.from_string("paper").evaluate(truth, data.geometry).dop
    data.dop = np.clip(dop + NOISE * rng.standard_normal(ANGLES.size), 0.0, 1.0)
    data.dop_err = np.full(ANGLES.size, NOISE)
    data.source = "synthetic specular-geometry DOP"
    return data


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="reports/table1")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(args.seed)
    model = Model.from_string("paper")
    fig = Figure(figsize=(10, 4), layout="constrained")
    axes = fig.subplots(1, 2)
    results, rows = {}, []
    for ax, (name, truth) in zip(axes, MATERIALS.items()):
        data = make_data(truth, rng)
        posterior = Posterior.build(data, model)
        ga = optimize("ga", PaperObjective(data, model, PriorSet(model.parameters)), rng, model.name)
        inv = invert(posterior, seed=args.seed, progress=False, max_steps=60000)
        q = inv.summary.parameters
        results[name] = {"truth": truth, "ga": ga.best, "ga_objective": ga.objective, "ga_evaluations": ga.n_evaluations,
                         "ga_stop": ga.info["stop_reason"], "posterior": q, "diagnostics": inv.summary.diagnostics,
                         "identifiability": inv.summary.identifiability["findings"]}
        for p in ("n", "k", "sigma", "ks", "rho_d"):
            rows.append(f"| {name} | {p} | {truth[p]:.4g} | {ga.best[p]:.4g} | {q[p]['median']:.4g} "
                        f"[{q[p]['q05']:.4g}, {q[p]['q95']:.4g}] | "
                        f"{'yes' if q[p]['q05'] <= truth[p] <= q[p]['q95'] else 'no'} |")
        fine = Geometry(np.linspace(5, 85, 161), np.linspace(5, 85, 161), np.full(161, 180.0))
        ax.errorbar(data.theta_i, data.dop, yerr=data.dop_err, fmt="o", ms=3, color="k", label="synthetic data")
        ax.plot(fine.theta_i, model.evaluate(truth, fine).dop, "k-", lw=1, label="truth")
        ax.plot(fine.theta_i, model.evaluate(ga.best, fine).dop, "C3--", lw=1.2, label="paper's GA")
        flat = inv.result.flat_samples()
        draws = flat[rng.choice(len(flat), min(400, len(flat)), replace=False)]
        band = model.evaluate(posterior.priors.to_params(draws), fine).dop
        lo, hi = np.percentile(band, [5, 95], axis=0)
        ax.fill_between(fine.theta_i, lo, hi, color="C0", alpha=0.3, label="posterior 90 % band")
        ax.set_title(f"{name}: n = {truth['n']}, k = {truth['k']}")
        ax.set_xlabel("theta_i = theta_r (deg), specular geometry")
        ax.set_ylabel("DOP")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    save_figure(fig, out / "dop_curves.png")
    write_json(out / "table1.json", results)
    (out / "table1_rows.md").write_text(
        "| material | parameter | truth | paper's GA | posterior median [90 %] | truth inside |\n|---|---|---|---|---|---|\n"
        + "\n".join(rows) + "\n", encoding="utf-8")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
