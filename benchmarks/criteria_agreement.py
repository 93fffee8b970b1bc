"""Do PSIS-LOO and the evidence pick the same change? (issue 25, item 4)

    python benchmarks/criteria_agreement.py [--cases all | --cases N] [--out reports/criteria]

On the hidden-effect validation suite (``spacepol.validation.hidden_effects``: data from ``paper + E`` with known
noise, and null sets), ``diagnose`` from ``paper`` with every registered candidate and ``criterion="evidence"``:
each refitted change then holds both delta ELPD-LOO (+- SE) and the ln Bayes factor (+- error; Laplace-IS where its
weights are trusted, else nested sampling). From the same refits, the LOO rule picks the best change with delta >
2 SE and > 4, the evidence rule the best with ln B > 3 and > 2 errors. By default one case per effect (its first
value at the lower noise) and four null sets; ``--cases all``: the whole suite. Prints one line per case, the
agreement rate, and writes ``criteria.json``, ``criteria.md`` (the table) and ``criteria.png`` (delta ELPD-LOO
against ln B for every refitted change, both thresholds drawn). Each finished case is kept in
``criteria.partial.json``: the same command after a stop continues with the cases not yet done.
"""

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np


def _pick(ranking, key, error, rule):
    best = [e for e in ranking if e.get(key) is not None and rule(e[key], e[error])]
    return max(best, key=lambda e: e[key])["change"] if best else "none"


def _twins(a: str, b: str) -> bool:
    """Whether two picks add effects that declare each other twins (equal fits on DOP and BRDF: LOO ties them)."""
    from spacepol.physics.registry import registry

    names = [label.split()[-1] for label in (a, b)]
    if "none" in (a, b) or a == b:
        return False
    return names[1] in registry.get(names[0]).twins or names[0] in registry.get(names[1]).twins


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", default="default", help="'all', or how many of the default selection")
    ap.add_argument("--out", default="reports/criteria")
    ap.add_argument("--report-only", action="store_true", help="write the table and figure from the cases done so far "
                                                                 "(criteria.partial.json), running none")
    ap.add_argument("--merge", default=None, metavar="DIR", help="add the finished cases of another --out folder first")
    ap.add_argument("--start", type=int, default=1, help="begin at this case (1-based): a second process on the other "
                                                          "core takes the later cases into its own --out")
    args = ap.parse_args()
    from spacepol import configure_process

    configure_process(small_calls=True)
    from matplotlib.figure import Figure

    from spacepol.criticism.criteria import significant, significant_evidence
    from spacepol.criticism.diagnose import diagnose
    from spacepol.validation.hidden_effects import BASE, measurement, suite
    from spacepol.physics import Model

    cases = suite()
    if args.cases != "all":
        first = {}
        for c in cases:
            if c.effect is not None and c.effect not in first:
                first[c.effect] = c
        cases = list(first.values()) + [c for c in cases if c.effect is None][:4]
        if args.cases != "default":
            cases = cases[: int(args.cases)]
    print(f"load average before: {os.getloadavg()[0]:.2f}; {len(cases)} cases", flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    partial = out / "criteria.partial.json"  # each finished case, so a stopped run continues with the same command
    done = json.loads(partial.read_text()) if partial.exists() else {"cases": [], "refits": []}
    if args.merge:
        other = json.loads((Path(args.merge) / "criteria.partial.json").read_text())
        known = {r["case"] for r in done["cases"]}
        done["cases"] += [r for r in other["cases"] if r["case"] not in known]
        done["refits"] += [p for p in other["refits"] if p["case"] not in known]
        partial.write_text(json.dumps(done, indent=1))
    rows, points, start = done["cases"], done["refits"], time.perf_counter()
    finished = {r["case"] for r in rows}
    if args.report_only:
        order = {c.label: k for k, c in enumerate(cases)}
        rows.sort(key=lambda r: order.get(r["case"], len(order)))
        cases = []
    for k, case in enumerate(cases, start=1):
        if k < args.start:
            continue
        if case.label in finished:
            print(f"[{k}/{len(cases)}] {case.label:<28s} done before", flush=True)
            continue
        t = time.perf_counter()
        report = diagnose(measurement(case), Model.from_string(BASE), np.random.default_rng(case.seed), seed=0,
                          progress=False, criterion="evidence")
        ranking = report["ranking"]
        loo = _pick(ranking, "delta_elpd", "delta_elpd_se", significant)
        evidence = _pick(ranking, "delta_log_evidence", "delta_log_evidence_error", significant_evidence)
        nested = sum(1 for e in ranking if e.get("posterior", {}).get("engine") not in (None, "laplace-is"))
        rows.append({"case": case.label, "hidden": case.effect or "none", "loo": loo, "evidence": evidence,
                     "agree": loo == evidence, "twins": _twins(loo, evidence), "refits_by_emcee_and_nested": nested,
                     "seconds": time.perf_counter() - t})
        points += [{"case": case.label, "change": e["change"], "delta_elpd": e["delta_elpd"], "se": e["delta_elpd_se"],
                    "delta_log_evidence": e["delta_log_evidence"], "error": e["delta_log_evidence_error"]}
                   for e in ranking if e.get("delta_log_evidence") is not None and e["delta_elpd"] is not None]
        print(f"[{k}/{len(cases)}] {case.label:<28s} LOO: {loo:<32s} evidence: {evidence:<32s} "
              f"{'agree' if loo == evidence else 'twins' if rows[-1]['twins'] else 'DIFFER'} ({rows[-1]['seconds']:.0f} s)",
              flush=True)
        partial.write_text(json.dumps({"cases": rows, "refits": points}, indent=1))
    agree = sum(r["agree"] for r in rows)
    print(f"the two criteria pick the same change in {agree} of {len(rows)} cases; {time.perf_counter() - start:.0f} s; "
          f"load average after: {os.getloadavg()[0]:.2f}")
    (out / "criteria.json").write_text(json.dumps({"cases": rows, "refits": points}, indent=1))
    lines = ["| case | hidden | LOO picks | evidence picks | same |", "|---|---|---|---|---|"]
    lines += [f"| {r['case']} | {r['hidden']} | {r['loo']} | {r['evidence']} | "
              f"{'yes' if r['agree'] else 'twins' if r['twins'] else '**no**'} |" for r in rows]
    lines.append(f"\nSame change in {agree} of {len(rows)} cases; where not, twins (declared, tied by LOO) in "
                 f"{sum(r['twins'] for r in rows)}.")
    (out / "criteria.md").write_text("\n".join(lines) + "\n")
    fig = Figure(figsize=(5.5, 4.5), layout="constrained")
    ax = fig.subplots()
    x = np.array([p["delta_elpd"] for p in points])
    y = np.array([p["delta_log_evidence"] for p in points])
    ax.scatter(np.sign(x) * np.log1p(np.abs(x)), np.sign(y) * np.log1p(np.abs(y)), s=12)
    ax.axvline(np.log1p(4), color="C1", lw=0.8, label="LOO threshold (4)")
    ax.axhline(np.log1p(3), color="C2", lw=0.8, label="evidence threshold (ln B 3)")
    ax.set_xlabel("delta ELPD-LOO (sign x log(1 + |x|))")
    ax.set_ylabel("ln Bayes factor (sign x log(1 + |x|))")
    ax.set_title(f"every refitted change of {len(rows)} cases", fontsize=9)
    ax.legend(fontsize=7)
    fig.savefig(out / "criteria.png", dpi=110)


if __name__ == "__main__":
    main()
