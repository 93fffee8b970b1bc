"""Validation of `diagnose` on synthetic data with a hidden effect (issue 4's acceptance).

    python benchmarks/hidden_effect_suite.py [--jobs 2] [--out reports/validation] [--swaps]

Every built-in effect that composes with the paper model, two values x two noise levels, two
angle samplings and two materials alternating, plus 8 null sets; `diagnose` with the whole
library on each. Prints one line per case and the rates; writes hidden_effects.json/.md/.png.
About 1 min per case on this machine (40 cases: ~40 min with --jobs 1, ~25 min with --jobs 2).

``--swaps`` runs the swap cases of issue 10 instead (data from specular+smith+lambertian + E, diagnose
--rounds 4 from paper; ``spacepol.criticism.swap_suite``): ~4-5 min per case; writes swap_cases.json/.md.
"""

import argparse
import json
import time
from pathlib import Path

from spacepol.criticism.hidden_effects import detection_figure, run_suite, suite, summarise
from spacepol.io.atomic import save_figure, write_json


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--out", default="reports/validation")
    ap.add_argument("--effects", nargs="*")
    ap.add_argument("--swaps", action="store_true", help="the swap cases (diagnose --rounds from paper)")
    args = ap.parse_args()
    start = time.perf_counter()
    if args.swaps:
        return swaps(args, start)
    rows = run_suite(suite(args.effects), jobs=args.jobs)
    summary = summarise(rows)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_json(out / "hidden_effects.json", {"summary": summary, "cases": rows, "seconds": time.perf_counter() - start})
    save_figure(detection_figure(rows), out / "hidden_effects.png")
    lines = ["| case | material | sampling | size/noise | verdict | tied with | correct | chi2_red after | hidden parameter in 90 % |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        size = "null" if r["effect"] == "none" else f"{r['size']:.2f}"
        lines.append(f"| {r['label']} | {r['material']} | {r['sampling']} | {size} | {r['verdict']} | "
                     f"{', '.join(r['tied_with'])} | {'yes' if r['correct'] else 'NO'} | "
                     f"{r['chi2_red_after']:.2f} | {r['covered']} |" if "chi2_red_after" in r else
                     f"| {r['label']} | {r['material']} | {r['sampling']} | {size} | {r['verdict']} | "
                     f"{', '.join(r['tied_with'])} | {'yes' if r['correct'] else 'NO'} | | |")
    (out / "hidden_effects.md").write_text("\n".join(lines) + "\n\n" + json.dumps(summary, indent=1) + "\n")
    print(json.dumps(summary, indent=1))
    print(f"{time.perf_counter() - start:.0f} s; wrote {out}/hidden_effects.json, .md, .png")


def _swap_row(case):
    from spacepol.criticism.swap_suite import run_swap_case

    return run_swap_case(case)


def swaps(args, start):
    from concurrent.futures import ProcessPoolExecutor

    from spacepol.criticism.swap_suite import swap_suite

    cases = swap_suite()
    with ProcessPoolExecutor(args.jobs) as pool:
        rows = []
        for k, row in enumerate(pool.map(_swap_row, cases)):
            rows.append(row)
            print(f"[{k + 1}/{len(cases)}] {row['label']:<24s} {' -> '.join(row['path']) or '(no change)'}; "
                  f"chi2_red {row['chi2_red_final']:.2f} {'ok' if row['correct'] else 'WRONG'}", flush=True)
    rate = sum(r["correct"] for r in rows) / len(rows)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_json(out / "swap_cases.json", {"correct_rate": rate, "cases": rows, "seconds": time.perf_counter() - start})
    lines = ["| case | material | sampling | path | final chi2_red | correct |", "|---|---|---|---|---|---|"]
    lines += [f"| {r['label']} | {r['material']} | {r['sampling']} | {' -> '.join(r['path'])} | {r['chi2_red_final']:.2f} | "
              f"{'yes' if r['correct'] else 'NO'} |" for r in rows]
    (out / "swap_cases.md").write_text("\n".join(lines) + f"\n\ncorrect: {rate:.2f}\n")
    print(f"correct {sum(r['correct'] for r in rows)}/{len(rows)}; {time.perf_counter() - start:.0f} s; wrote {out}/swap_cases.json, .md")


if __name__ == "__main__":
    main()
