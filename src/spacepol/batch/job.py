"""One set of a batch: ``invert-mcmc run`` on it, in its own folder, and its row of the results table.

Runs in a worker process (a pool's or a Dask worker's): it takes and returns plain data, catches every
failure of the set (bad file, model, prior, a bug) and reports it in the row instead of raising, so one
broken set never stops the others.
"""

from __future__ import annotations

import contextlib
import io
import json
import time
from pathlib import Path

from .manifest import BatchJob

SETTINGS_FILE = "batch_settings.json"


def run_job(job: BatchJob, out: str) -> dict:
    """Invert one set into ``out/<id>/`` (``api.invert``); the results row ``{id, status, seconds, error, summary}``."""
    from .._runtime import configure_process
    from ..api import invert, load
    from ..errors import SpacepolError

    configure_process(small_calls=True)  # a fresh worker (Dask's) before its first computation; elsewhere a no-op

    folder = Path(out) / job.id
    start = time.perf_counter()
    try:
        data = load(job.data, job.wavelength_um)
        with contextlib.redirect_stdout(io.StringIO()):
            invert(data, job.model, job.prior, "emcee", job.seed, folder, observables=job.observables)
        summary = json.loads((folder / "summary.json").read_text(encoding="utf-8"))  # as the table's later readers see it
        (folder / SETTINGS_FILE).write_text(json.dumps(job.settings(), indent=1), encoding="utf-8")
        return {"id": job.id, "status": "ok", "seconds": time.perf_counter() - start, "error": "",
                "summary": summary}
    except (SpacepolError, OSError) as exc:
        error = str(exc)
    except Exception as exc:  # a bug of ours: still one line, and the other sets go on
        error = f"internal error: {type(exc).__name__}: {exc}"
    return {"id": job.id, "status": "failed", "seconds": time.perf_counter() - start, "error": error.splitlines()[0], "summary": None}


def finished(job: BatchJob, out: str) -> dict | None:
    """The stored summary of a set a previous batch finished with the same settings, else None."""
    folder = Path(out) / job.id
    try:
        settings = json.loads((folder / SETTINGS_FILE).read_text(encoding="utf-8"))
        summary = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return summary if settings == job.settings() else None
