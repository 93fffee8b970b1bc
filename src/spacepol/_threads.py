"""One BLAS thread unless the user says otherwise.

spacepol's linear algebra is on matrices the size of the parameter vector (L-BFGS-B's updates,
covariances), where BLAS threads cannot help; but they spin while numba's threads hold the cores,
and each tiny call then waits for a time slice. Measured on this 2-core machine: L-BFGS-B polishing
of the paper model 40x slower (0.3 s instead of 7 ms per start), one diagnose round 71 s -> 31 s.
Set before numpy or scipy load BLAS (the environment variable); libraries already loaded are limited
through threadpoolctl. An explicit OPENBLAS_NUM_THREADS / OMP_NUM_THREADS / MKL_NUM_THREADS is kept.
"""

import os

_VARIABLES = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS")


def limit_blas_threads() -> None:
    if any(v in os.environ for v in _VARIABLES):
        return
    os.environ["OPENBLAS_NUM_THREADS"] = "1"
    os.environ["MKL_NUM_THREADS"] = "1"
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # pragma: no cover - a declared dependency
        return
    threadpool_limits(1, user_api="blas")
