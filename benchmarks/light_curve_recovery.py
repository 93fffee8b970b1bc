"""Material and attitude from a light curve, on renders with hidden truths: several materials and attitudes, passes of
the bundled ISS elements over several sites, by day and in twilight.

For each case a four-face box (faces of unequal areas) of one library material (its parameters drawn from that
material's own priors) under a random attitude offset (each angle uniform within 40 deg) is rendered by
``synth_pass`` (photon noise, scintillation, and a camera calibrated to ``--polarimetric-accuracy`` in q and u) and
inverted by ``invert_lightcurve`` against all four materials, once with flux, DoLP and AoP and
once with the flux alone (the control that makes the paper's point). Printed per case: the true material's rank and
its ELPD-LOO gap to the runner-up in SEs of the paired difference (goal: first by >= 2 SE), the curve's times and
median signal-to-noise of flux and DoLP (what it can carry), each attitude offset's
90 % interval against the truth (goal: it holds the truth and is narrower than 30 deg), the ln Z gap, nested
sampling's effective draws; then the coverage of all 90 % intervals (the attitude posterior's calibration) and the
two gaps side by side.

    python benchmarks/light_curve_recovery.py [--cases 5] [--live 500] [--seed 0] [--polarimetric-accuracy 0.005]
        [--out reports/light_curve_recovery]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import tempfile
import time
from datetime import datetime, timedelta, timezone
from pathlib import Path

import numpy as np

import spacepol
from spacepol.camera.sensor import Camera
from spacepol.detect.materials import LIBRARY, material
from spacepol.orbit import Attitude, Face, pass_geometry, read_tle, write_target
from spacepol.paths import bundled

TLE = bundled("tle", "iss_zarya_2014-01-20.tle")
SITES = {"Changchun": (43.1333, 125.5333, 200.0), "Albuquerque": (35.08, -106.65, 1600.0), "Perth": (-31.95, 115.86, 20.0),
         "La Palma": (28.76, -17.89, 2300.0), "Santiago": (-33.45, -70.66, 570.0), "Tokyo": (35.68, 139.69, 40.0)}
# faces of unequal areas, so that no turn maps the box onto itself
BOX = [("nadir", 3.0, (0, 0, 1)), ("starboard", 2.0, (0, 1, 0)), ("port", 1.0, (0, -1, 0)), ("ram", 1.5, (1, 0, 0))]
ANGLES = ("yaw_deg", "pitch_deg", "roll_deg")


def passes(site, days: int = 12, min_elevation: float = 30.0) -> list[tuple]:
    """(start, end, sky) of the ISS's visible passes over ``site`` (above 10 deg and sunlit, culminating above
    ``min_elevation``) in ``days`` days from the elements' epoch; sky: day or twilight at culmination."""
    first = datetime(2014, 1, 20, 12, tzinfo=timezone.utc)
    g = pass_geometry(read_tle(TLE), site, first, first + timedelta(days=days), 30.0)
    seen = (g.elevation_deg > 10) & g.sunlit
    out, k = [], 0
    while k < len(seen):
        if not seen[k]:
            k += 1
            continue
        j = k
        while j + 1 < len(seen) and seen[j + 1]:
            j += 1
        top = k + int(np.argmax(g.elevation_deg[k : j + 1]))
        if g.elevation_deg[top] >= min_elevation and j - k >= 8:
            sky = "day" if g.sun_elevation_deg[top] > -0.833 else "twilight"
            out.append((g.times_utc[k], g.times_utc[j], sky))
        k = j + 1
    return out


def box_toml(path: Path, values: dict | None, attitude: dict | None) -> Path:
    """The box of ``BOX``, of the material ``values`` (None: unknown), under ``attitude`` (None: no table)."""
    faces = [Face(name, area, "nadir", normal, values or None) for name, area, normal in BOX]
    return write_target(path, faces, None if attitude is None else Attitude(**attitude))


def cases(count: int, rng: np.random.Generator) -> list[dict]:
    """``count`` cases cycling through the materials, over passes alternating day and twilight across the sites."""
    found = {name: passes(site) for name, site in SITES.items()}
    day = [(n, p) for n, ps in found.items() for p in ps if p[2] == "day"]
    dusk = [(n, p) for n, ps in found.items() for p in ps if p[2] == "twilight"]
    out = []
    for k in range(count):
        pool = dusk if (k % 2 and dusk) else day
        site_name, (start, end, sky) = pool[int(rng.integers(len(pool)))]
        name = list(LIBRARY)[k % len(LIBRARY)]
        m = material(name, 1.65)
        truth = {"model": m.model} | {p: float(prior.sample(rng)) for p, prior in m.priors.items()}
        attitude = dict(zip(ANGLES, rng.uniform(-40, 40, 3).round(1)))
        out.append({"material": name, "truth": truth, "attitude": attitude, "site": site_name, "sky": sky,
                    "start": start.strftime("%Y-%m-%dT%H:%M:%SZ"), "end": end.strftime("%Y-%m-%dT%H:%M:%SZ")})
    return out


def run_case(case: dict, folder: Path, live: int, seed: int, polarimetric_accuracy: float) -> dict:
    site = ",".join(str(v) for v in SITES[case["site"]])
    csv = folder / "pass.csv"
    camera = Camera(exposure_set=False, polarimetric_accuracy=polarimetric_accuracy)  # the exposure set for the pass
    curve = spacepol.synth_pass(TLE, site, case["start"], case["end"], target=box_toml(folder / "true.toml", case["truth"],
                                case["attitude"]), step_s=20.0, camera=camera, seed=seed, out=csv)
    unknown = box_toml(folder / "unknown.toml", None, None)
    # what the curve can carry: a pass of few times with its polarization at the noise cannot separate the materials
    row = {"times": len(curve), "flux_snr": float(np.median(curve.flux / curve.flux_err)),
           "dolp_snr": float(np.median(np.abs(curve.dolp) / curve.dolp_err))}
    for label, observables in (("polarization", None), ("flux only", ["flux"])):
        start = time.perf_counter()
        inv = spacepol.invert_lightcurve(csv, TLE, site, case["start"], case["end"], target=unknown,
                                         materials=list(LIBRARY), observables=observables, live=live, seed=seed,
                                         progress=True)
        ranking = inv.ranking
        rank = [r["material"] for r in ranking].index(case["material"]) + 1
        rival = ranking[1] if rank == 1 else ranking[0]
        true_row = ranking[rank - 1]
        diff = true_row["delta_elpd"] - rival["delta_elpd"]
        se = max(rival["delta_elpd_se"], true_row["delta_elpd_se"])
        fit = next(f for f in inv.fits if f.material == case["material"]).summary()
        row[label] = {"rank": rank, "gap_se": diff / se if se > 0 else float("inf"), "gap": diff,
                      "attitude": {a: fit[a] for a in ANGLES}, "seconds": time.perf_counter() - start,
                      "effective_min": min(f.effective_draws for f in inv.fits),
                      "ended_early": [f.material for f in inv.fits if f.exploration_ended_early],
                      "log_evidence_gap": true_row["delta_log_evidence"] - rival["delta_log_evidence"]}
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=5)
    ap.add_argument("--live", type=int, default=500)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--polarimetric-accuracy", type=float, default=0.005,
                    help="the camera's calibration accuracy in q and u (0: photon noise only)")
    ap.add_argument("--out", default="reports/light_curve_recovery")
    args = ap.parse_args()
    spacepol.configure_process(small_calls=True)
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.2f}; "
          f"polarimetric accuracy {args.polarimetric_accuracy:g}, scintillation as synth-pass renders it", flush=True)
    rng = np.random.default_rng(args.seed)
    rows, covered, widths = [], [], []
    for k, case in enumerate(cases(4 * len(LIBRARY) * args.cases, rng)):  # room for skipped passes
        if len(rows) == args.cases:
            break
        if len(rows) % len(LIBRARY) != k % len(LIBRARY):  # keep the materials in turn after a skipped case
            continue
        with tempfile.TemporaryDirectory() as tmp:
            try:
                row = run_case(case, Path(tmp), args.live, args.seed + k, args.polarimetric_accuracy)
            except spacepol.SpacepolError as exc:  # no lit face turned to the site on that pass: another pass
                print(f"  skipped {case['material']} over {case['site']} ({case['sky']}): {exc}", flush=True)
                continue
        rows.append(case | row)
        pol, flux = row["polarization"], row["flux only"]
        intervals = []
        for a in ANGLES:
            q = pol["attitude"][a]
            covered.append(q["q05"] <= case["attitude"][a] <= q["q95"])
            widths.append(q["q95"] - q["q05"])
            intervals.append(f"{a[:-4]} {case['attitude'][a]:+.1f} in [{q['q05']:+.2f}, {q['q95']:+.2f}]")
        print(f"{case['material']:<12s} {case['site']:<11s} {case['sky']:<8s} {row['times']:3d} times (median SNR: flux {row['flux_snr']:.0f}, DoLP {row['dolp_snr']:.1f}): rank {pol['rank']} "
              f"gap {pol['gap_se']:+.1f} SE (flux only: rank {flux['rank']}, {flux['gap_se']:+.1f} SE); "
              f"{'; '.join(intervals)}; ln Z gap {pol['log_evidence_gap']:+.1f} (flux only {flux['log_evidence_gap']:+.1f}); "
              f"effective draws >= {pol['effective_min']:.0f}; explorations ended where they stood: "
              f"{', '.join(pol['ended_early']) or 'none'} (flux only: {', '.join(flux['ended_early']) or 'none'}); "
              f"{pol['seconds']:.0f} + {flux['seconds']:.0f} s",
              flush=True)
    n = len(covered)
    if not n:
        print("no case could be rendered")
        return
    print(f"\n90 % attitude intervals holding the truth: {sum(covered)}/{n} ({100 * sum(covered) / n:.0f} %; a binomial "
          f"90 % range for {n} intervals: {np.percentile(np.random.default_rng(1).binomial(n, 0.9, 100000), [5, 95])}); "
          f"widths {min(widths):.2f}-{max(widths):.2f} deg")
    print(f"true material first by >= 2 SE: {sum(r['polarization']['rank'] == 1 and r['polarization']['gap_se'] >= 2 for r in rows)}"
          f"/{len(rows)} with polarization, {sum(r['flux only']['rank'] == 1 and r['flux only']['gap_se'] >= 2 for r in rows)}"
          f"/{len(rows)} with the flux alone; median gap {np.median([r['polarization']['gap_se'] for r in rows]):.1f} SE "
          f"against {np.median([r['flux only']['gap_se'] for r in rows]):.1f} SE")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "recovery.json").write_text(json.dumps(rows, indent=1, default=str))
    print(f"load after {os.getloadavg()[0]:.2f}; wrote {out}/recovery.json")


if __name__ == "__main__":
    main()
