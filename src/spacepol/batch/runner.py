"""``invert-mcmc batch``: read the manifest, skip the sets already finished, run the rest, keep the table."""

from __future__ import annotations

import os
import sys
import time

from ..errors import ParameterError
from ..io.output import check_output_dir, folder_lock
from . import executors
from .job import finished
from .manifest import read_manifest
from .results import table_row, write_results


def run_batch(manifest, out, executor: str = "local", scheduler: str | None = None, workers: int | None = None,
              progress: bool = True) -> list[dict]:
    """Run every set of ``manifest`` into ``out/<id>/``; returns the rows of ``out/results.csv``."""
    if executor not in ("local", "dask"):
        raise ParameterError(f"--executor {executor}: use local or dask")
    if scheduler and executor != "dask":
        raise ParameterError("--scheduler is the address of a Dask scheduler: use it with --executor dask")
    jobs = read_manifest(manifest)
    out = check_output_dir(out)
    workers = workers or min(len(jobs), os.cpu_count() or 1)
    rows = {}
    with folder_lock(out, what="batch"):
        todo = []
        for job in jobs:
            summary = finished(job, str(out))
            if summary is None:
                todo.append(job)
            else:
                rows[job.id] = table_row({"id": job.id, "status": "skipped", "seconds": 0.0, "summary": summary})
        ordered = lambda: [rows[j.id] for j in jobs if j.id in rows]  # noqa: E731 (manifest order)
        say = (lambda text: print(text, file=sys.stderr)) if progress else (lambda text: None)
        say(f"batch: {len(jobs)} sets, {len(rows)} already finished (skipped), {len(todo)} to run on "
            f"{'a Dask cluster' if executor == 'dask' else 'a local process pool'}"
            + ("" if scheduler else f" of {workers} workers"))
        write_results(out / "results.csv", ordered())
        start, done = time.perf_counter(), 0

        def on_done(outcome):
            nonlocal done
            done += 1
            rows[outcome["id"]] = table_row(outcome)
            write_results(out / "results.csv", ordered())
            extra = (f"R-hat {rows[outcome['id']]['rhat_max'][:6]}" if outcome["status"] == "ok" else outcome["error"])
            say(f"  [{done}/{len(todo)}] {outcome['id']}: {outcome['status']} in {outcome['seconds']:.1f} s ({extra}); "
                f"{time.perf_counter() - start:.0f} s elapsed")

        if todo:
            if executor == "dask":
                executors.run_dask(todo, str(out), workers, scheduler, on_done)
            else:
                executors.run_local(todo, str(out), workers, on_done)
    return ordered()
