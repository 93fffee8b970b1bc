"""Where the jobs run: a local process pool (default) or a Dask distributed cluster.

Both call ``on_done(outcome)`` as each set finishes, in completion order. Workers are separate processes
(spawned, not forked: JAX is multithreaded) with one compute thread each, so W workers use W cores
without oversubscribing them. A worker process that dies (killed, out of memory) fails its set only.
"""

from __future__ import annotations

import os
from contextlib import contextmanager

from ..errors import SpacepolError
from .job import run_job

# XLA's own threads off in the workers: the pool is the parallelism
_WORKER_ENV = {"XLA_FLAGS": "--xla_cpu_multi_thread_eigen=false intra_op_parallelism_threads=1",
               "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


@contextmanager
def _worker_environment():
    """Environment the worker processes inherit (set while they start, restored after)."""
    saved = {k: os.environ.get(k) for k in _WORKER_ENV}
    os.environ.update({k: v for k, v in _WORKER_ENV.items() if k not in os.environ or k == "XLA_FLAGS"})
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def _failed(job, exc) -> dict:
    return {"id": job.id, "status": "failed", "seconds": 0.0, "summary": None,
            "error": f"worker lost: {type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}".rstrip(": ")}


def _collect(futures: dict, as_completed, on_done) -> None:
    """``on_done`` for each job as it finishes; a worker that died with its set (BrokenProcessPool,
    Dask's KilledWorker) fails that set only."""
    for future in as_completed(futures):
        try:
            outcome = future.result()
        except Exception as exc:
            outcome = _failed(futures[future], exc)
        on_done(outcome)


def run_local(jobs, out: str, workers: int, on_done) -> None:
    """Run the jobs on a local pool of ``workers`` spawned processes; ``on_done(row)`` as each finishes."""
    from concurrent.futures import as_completed

    from .._runtime import spawned_pool

    with _worker_environment():
        pool = spawned_pool(workers)
    try:
        _collect({pool.submit(run_job, job, out): job for job in jobs}, as_completed, on_done)
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def run_dask(jobs, out: str, workers: int, scheduler: str | None, on_done) -> None:
    """Run the jobs on a Dask cluster (``scheduler``: its address; None starts a local one with ``workers``);
    ``on_done(row)`` as each finishes."""
    try:
        from distributed import Client, LocalCluster, as_completed
    except ImportError:
        raise SpacepolError("--executor dask needs Dask's distributed scheduler: pip install 'spacepol[dask]'") from None
    cluster = None
    with _worker_environment():
        if scheduler:
            try:
                client = Client(scheduler, timeout="10s")
            except (OSError, TimeoutError) as exc:
                raise SpacepolError(f"--scheduler {scheduler}: no Dask scheduler answers there ({exc})") from None
        else:
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
            client = Client(cluster)
    try:
        _collect({client.submit(run_job, job, out, key=f"spacepol-batch-{job.id}", pure=False): job for job in jobs},
                 as_completed, on_done)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
