"""Many inversions at once: ``invert-mcmc batch MANIFEST.csv`` (DESIGN.md's contract).

``manifest`` reads and checks the manifest (one row per data set), ``job`` runs one set exactly as
``invert-mcmc run`` would and returns its row of the results table, ``executors`` runs the jobs on a local
process pool or a Dask cluster, ``results`` writes ``results.csv`` and knows which sets are finished.
"""

from .manifest import BatchJob, read_manifest
from .runner import run_batch

__all__ = ["BatchJob", "read_manifest", "run_batch"]
