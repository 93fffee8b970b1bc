"""Calibration of the light-curve attitude posterior: are its intervals as wide as its errors?

    python benchmarks/light_curve_calibration.py [--renders 20] [--material solar_glass] [--live 150] [--seed 0]
        [--out reports/light_curve_calibration]
    python benchmarks/light_curve_calibration.py --summarize reports/light_curve_calibration/ranks.json

Each render draws the material's parameters from its own priors and the attitude offsets from the inversion's prior
(uniform within 60 deg), renders the box of ``light_curve_recovery.BOX`` by ``synth_pass`` over a daytime ISS pass
of the paper's site every 30 s, and inverts it against the true material alone. Where the posterior is calibrated,
the rank of each true offset among its posterior draws is uniform. Printed per angle (renders are independent): the
coverage of the 50 % and 90 % central intervals against their binomial ranges and a Kolmogorov-Smirnov test of the
ranks; the ranks' correlation between angles over renders; and the pooled coverage of all angles, whose binomial range
holds only where the angles of one render are independent (a render's yaw and pitch can trade along one valley of
the posterior). The ranks go to ``--out``/ranks.json; ``--summarize`` prints the summary of such a file. Renders whose
light is too faint to measure at any time are skipped and counted; a fit that stalls past its restarts is counted
apart; a fit whose exploration missed the mirrored attitude, sampled then in a second run (``fit_material``), is
named with that mode's share of the posterior.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy import stats

sys.path.insert(0, str(Path(__file__).parent))
from light_curve_recovery import TLE, box_toml  # noqa: E402

import spacepol  # noqa: E402
from spacepol.detect.light_curve_model import ATTITUDE_LIMIT_DEG  # noqa: E402
from spacepol.detect.materials import material  # noqa: E402

SITE = "43.1333,125.5333,200"
START, END = "2014-01-21T00:32:00Z", "2014-01-21T00:41:00Z"
ANGLES = ("yaw_deg", "pitch_deg", "roll_deg")


def one_render(name: str, rng: np.random.Generator, folder: Path, live: int, seed: int) -> dict:
    """The true offsets' ranks (share of draws below the truth) of one render, and the seconds it took."""
    m = material(name, 1.65)
    truth = {"model": m.model} | {p: float(prior.sample(rng)) for p, prior in m.priors.items()}
    attitude = dict(zip(ANGLES, rng.uniform(-ATTITUDE_LIMIT_DEG, ATTITUDE_LIMIT_DEG, 3)))
    start = time.perf_counter()
    spacepol.synth_pass(TLE, SITE, START, END, target=box_toml(folder / "true.toml", truth, attitude), step_s=30.0,
                        seed=seed, out=folder / "pass.csv")
    inv = spacepol.invert_lightcurve(folder / "pass.csv", TLE, SITE, START, END, target=box_toml(folder / "u.toml", None, None),
                                     materials=name, live=live, seed=seed, step_s=30.0)
    fit = inv.fits[0]
    ranks = {a: float(np.mean(fit.samples[:, fit.names.index(a)] < attitude[a])) for a in ANGLES}
    return {"ranks": ranks, "seconds": time.perf_counter() - start, "added": fit.added_attitude, "restarts": fit.restarts}


def summary(ranks: np.ndarray) -> list[str]:
    """The calibration's lines for ``ranks`` (renders, angles): per angle the 50 % and 90 % intervals' coverage against
    their binomial 90 % ranges and the ranks' KS p against uniform; the angles' rank correlations; the pooled
    coverage and the ranks of all angles in five bins."""
    n = len(ranks)
    levels = (0.5, 0.9)
    held = {level: np.abs(ranks - 0.5) <= level / 2 for level in levels}  # (renders, angles) per central interval
    lines = []
    for j, angle in enumerate(ANGLES):
        parts = []
        for level in levels:
            low, high = stats.binom.ppf([0.05, 0.95], n, level)
            parts.append(f"{level:.0%} intervals {int(held[level][:, j].sum())}/{n} (binomial 90 % range "
                         f"{low:.0f}-{high:.0f})")
        ks = stats.kstest(ranks[:, j], "uniform").pvalue
        lines.append(f"{angle}: {', '.join(parts)}; ranks' KS p = {ks:.2f}")
    rho = stats.spearmanr(ranks).correlation if n > 2 else np.full((len(ANGLES),) * 2, np.nan)
    pairs = [(0, 1), (0, 2), (1, 2)]
    lines.append("ranks' Spearman correlation over renders: " + ", ".join(
        f"{ANGLES[a][:-4]}-{ANGLES[b][:-4]} {rho[a, b]:+.2f}" for a, b in pairs)
        + " (the angles of one render are not independent where these are far from 0)")
    r = ranks.ravel()
    for level in levels:
        low, high = stats.binom.ppf([0.05, 0.95], r.size, level)
        # renders as clusters: the per-render counts' own variance over the binomial one (the design effect) widens
        # the pooled count's spread about its expectation (normal approximation)
        per_render = held[level].sum(axis=1)
        effect = max(1.0, float(per_render.var(ddof=1)) / (ranks.shape[1] * level * (1 - level))) if n > 1 else 1.0
        spread = 1.645 * np.sqrt(effect * r.size * level * (1 - level))
        lines.append(f"all angles pooled, {level:.0%} intervals: {int(per_render.sum())}/{r.size} (binomial range for "
                     f"independent intervals {low:.0f}-{high:.0f}; with the renders' design effect {effect:.2f}: "
                     f"{level * r.size - spread:.0f}-{level * r.size + spread:.0f})")
    counts = np.histogram(r, bins=5, range=(0, 1))[0]
    lines.append(f"all ranks in five bins: {counts.tolist()}; chi-square p = {stats.chisquare(counts).pvalue:.3f} "
                 "(for independent ranks)")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--renders", type=int, default=20)
    ap.add_argument("--material", default="solar_glass")
    ap.add_argument("--live", type=int, default=150)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default="reports/light_curve_calibration")
    ap.add_argument("--summarize", metavar="RANKS.json", help="print the summary of an earlier run's ranks and stop")
    args = ap.parse_args()
    if args.summarize:
        record = json.loads(Path(args.summarize).read_text())
        print("\n".join(summary(np.array(record["ranks"]))))
        return
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.2f}", flush=True)
    rng = np.random.default_rng(args.seed)
    ranks, skipped, stalled, added = [], 0, 0, 0
    for k in range(args.renders):
        with tempfile.TemporaryDirectory() as tmp:
            try:
                row = one_render(args.material, rng, Path(tmp), args.live, args.seed + k)
            except spacepol.SpacepolError as exc:
                skipped += 1
                print(f"  render {k}: skipped ({exc})", flush=True)
                continue
            except spacepol.SamplerStalled as exc:  # no posterior: a failure of the method, counted apart
                stalled += 1
                print(f"  render {k}: STALLED ({exc})", flush=True)
                continue
        ranks.append([row["ranks"][a] for a in ANGLES])
        added += row["added"] is not None
        print(f"  render {k}: ranks " + ", ".join(f"{a[:-4]} {row['ranks'][a]:.3f}" for a in ANGLES)
              + f" ({row['seconds']:.0f} s" + (f", {row['restarts']} restarts" if row["restarts"] else "") + ")", flush=True)
        if row["added"] is not None:
            print(f"    {row['added']['finding']}", flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "ranks.json").write_text(json.dumps({"angles": list(ANGLES), "ranks": ranks, "material": args.material,
                                                "live": args.live, "seed": args.seed}, indent=1))
    print("\n".join(summary(np.array(ranks).reshape(-1, len(ANGLES)))))
    print(f"{skipped} renders skipped, {stalled} stalled, {added} with a second attitude sampled in its own run; "
          f"load after {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
