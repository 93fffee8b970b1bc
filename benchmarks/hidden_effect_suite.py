"""The validation suite of model criticism (issues 4 and 10).

    python benchmarks/hidden_effect_suite.py [--jobs 2] [--out reports/validation] [--no-swaps | --only-swaps]

Hidden-effect cases (issue 4): every built-in effect that composes with the paper model, two values x
two noise levels, two angle samplings and two materials alternating, plus 8 null sets; data from
``paper + E``, `diagnose` with the whole library from ``paper``.

Swap cases (issue 10): data from ``specular+smith+lambertian + E`` (physical shadowing and a reciprocal
body term) for E in none, dop_bias, angle_offset, extinction, polarized_diffuse, ggx, two sets each;
`diagnose --rounds 4` from ``paper``, whose shadowing and body are wrong for these data
(``spacepol.validation.swap_suite``). Right = the path holds the shadowing swap and E (or a tied
twin), the nulls gain no addition, and the final reduced chi^2 < 1.5.

Prints one line per case and the rates; writes hidden_effects.json/.md/.png (both parts) and
criticism_verdicts.json (each case's verdict or path: ``tests/data/criticism_verdicts.json`` is such a record, made
by the code before a change meant to keep them; the slow swap test compares). A partial run
(``--effects``, ``--no-swaps``, ``--only-swaps``) updates the cases it ran in an existing
hidden_effects.json and keeps the others, so one part can be re-measured alone.
"""

import argparse
import json
import time
from pathlib import Path

from spacepol._runtime import spawned_pool
from spacepol.validation.hidden_effects import run_suite, suite, summarise
from spacepol.validation.swap_suite import run_swap_case, summarise_swaps, swap_suite
from spacepol.validation.verdicts import verdicts
from spacepol.criticism.explain import unconverged_words
from spacepol.io.atomic import save_figure, write_json
from spacepol.report.criticism_figures import validation_figure


def main():
    from spacepol import configure_process

    configure_process()  # the settings the command line makes
    ap = argparse.ArgumentParser()
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--out", default="reports/validation")
    ap.add_argument("--effects", nargs="*", help="hidden-effect cases of these effects only")
    which = ap.add_mutually_exclusive_group()
    which.add_argument("--no-swaps", action="store_true", help="the hidden-effect cases only")
    which.add_argument("--only-swaps", action="store_true", help="the swap cases only")
    args = ap.parse_args()
    start = time.perf_counter()
    rows = [] if args.only_swaps else run_suite(suite(args.effects), jobs=args.jobs)
    seconds_hidden = time.perf_counter() - start
    swap_rows = [] if args.no_swaps else run_swaps(args.jobs)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    previous = json.loads((out / "hidden_effects.json").read_text()) if (out / "hidden_effects.json").exists() else {}
    rows, swap_rows = _merge(previous.get("cases", []), rows), _merge(previous.get("swap_cases", []), swap_rows)
    summary = {**(summarise(rows) if rows else {}), **(summarise_swaps(swap_rows) if swap_rows else {})}
    write_json(out / "hidden_effects.json", {"summary": summary, "cases": rows, "swap_cases": swap_rows,
                                             "seconds": {"hidden": seconds_hidden, "total": time.perf_counter() - start}})
    write_json(out / "criticism_verdicts.json", verdicts(rows, swap_rows))
    save_figure(validation_figure(rows, swap_rows), out / "hidden_effects.png")
    (out / "hidden_effects.md").write_text(_table(rows) + _swap_table(swap_rows) + "\n" + json.dumps(summary, indent=1) + "\n")
    print(json.dumps(summary, indent=1))
    print(f"{time.perf_counter() - start:.0f} s; wrote {out}/hidden_effects.json, .md, .png")


def _merge(old: list[dict], new: list[dict]) -> list[dict]:
    """Rows of this run replace the stored rows of the same case; the other stored rows are kept."""
    fresh = {r["label"]: r for r in new}
    return [fresh.pop(r["label"], r) for r in old] + list(fresh.values())


def run_swaps(jobs: int) -> list[dict]:
    cases = swap_suite()
    rows = []
    with spawned_pool(jobs) as pool:
        for k, row in enumerate(pool.map(run_swap_case, cases)):
            rows.append(row)
            chi2 = " -> ".join(f"{c:.2f}" for c in row["chi2_red_per_round"])
            print(f"[swap {k + 1}/{len(cases)}] {row['label']:<24s} {' -> '.join(row['path']) or '(no change)'}; "
                  f"chi2_red {chi2} {'ok' if row['correct'] else 'WRONG'}", flush=True)
    return rows


def _table(rows) -> str:
    if not rows:
        return ""
    lines = ["## Hidden effects (data: paper + E; diagnose from paper)", "",
             "| case | material | sampling | size/noise | verdict | tied with | correct | chi2_red after | hidden parameter in 90 % |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        size = "null" if r["effect"] == "none" else f"{r['size']:.2f}"
        after = f"{r['chi2_red_after']:.2f} | {r['covered']}{_refit_words(r.get('refit'))}" if "chi2_red_after" in r else " | "
        lines.append(f"| {r['label']} | {r['material']} | {r['sampling']} | {size} | {r['verdict']} | "
                     f"{', '.join(r['tied_with'])} | {'yes' if r['correct'] else 'NO'} | {after} |")
    return "\n".join(lines) + "\n\n"


def _refit_words(refit) -> str:
    """Where the intervals came from a refit that did not converge, how far it got (``explain.unconverged_words``)."""
    if not refit or refit.get("converged", True):
        return ""
    return f" (the refit {unconverged_words(refit)})"


def _swap_table(rows) -> str:
    if not rows:
        return ""
    lines = ["## Swap cases (data: specular+smith+lambertian + E; diagnose --rounds 4 from paper)", "",
             "| case | material | sampling | path | reduced chi^2 per round | correct |", "|---|---|---|---|---|---|"]
    lines += [f"| {r['label']} | {r['material']} | {r['sampling']} | {' -> '.join(r['path']) or '(no change)'} | "
              f"{' -> '.join(f'{c:.2f}' for c in r['chi2_red_per_round'])} | {'yes' if r['correct'] else 'NO'} |" for r in rows]
    return "\n".join(lines) + "\n\n"


if __name__ == "__main__":
    main()
