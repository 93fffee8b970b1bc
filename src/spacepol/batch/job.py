"""One set of a batch: ``invert-mcmc run`` on it, in its own folder, and its row of the results table.

Runs in a worker process (a pool's or a Dask worker's): it takes and returns plain data, catches every
failure of the set (bad file, model, prior, a bug) and reports it in the row instead of raising, so one
broken set never stops the others.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import time
from pathlib import Path

from .manifest import BatchJob

SETTINGS_FILE = "batch_settings.json"


def run_job(job: BatchJob, out: str) -> dict:
    """Invert one set into ``out/<id>/``; the results row ``{id, status, seconds, error, summary}``."""
    from .._runtime import configure_process
    from ..cli import _wavelengths
    from ..errors import SpacepolError

    configure_process(small_calls=True)  # a fresh worker (Dask's) before its first computation; elsewhere a no-op

    folder = Path(out) / job.id
    start = time.perf_counter()
    args = argparse.Namespace(
        data=job.data, model=job.model, prior=job.prior, observables=job.observables, seed=job.seed,
        wavelength_um=None, dispersion=None, in_plane=False, walkers=None, steps=20000, restart=False,
        robust=False, quiet=True, reference=[], out=str(folder))
    try:
        if job.wavelength_um:
            args.wavelength_um = _wavelengths(job.wavelength_um)
        from .. import commands

        with contextlib.redirect_stdout(io.StringIO()):
            commands.run(args)
        summary = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
        (folder / SETTINGS_FILE).write_text(json.dumps(job.settings(), indent=1), encoding="utf-8")
        return {"id": job.id, "status": "ok", "seconds": time.perf_counter() - start, "error": "", "summary": summary}
    except (SpacepolError, argparse.ArgumentTypeError, OSError) as exc:
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
