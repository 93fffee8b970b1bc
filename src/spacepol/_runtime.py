"""Process-wide settings that decide speed on a small shared machine: one BLAS thread, and a heap that
keeps freed memory.

One BLAS thread unless the user says otherwise.

spacepol's linear algebra is on matrices the size of the parameter vector (L-BFGS-B's updates,
covariances), where BLAS threads cannot help; but they spin while the model's threads hold the cores,
and each tiny call then waits for a time slice. Measured on this 2-core machine: L-BFGS-B polishing
of the paper model 40x slower (0.3 s instead of 7 ms per start), one diagnose round 71 s -> 31 s.
Set before numpy or scipy load BLAS (the environment variable); libraries already loaded are limited
through threadpoolctl. An explicit OPENBLAS_NUM_THREADS / OMP_NUM_THREADS / MKL_NUM_THREADS is kept.

A heap that keeps freed memory (glibc): numpy's temporaries of a full-Mueller evaluation are megabytes
each (4 x 4 x walkers x geometries), above glibc's default mmap threshold, so every one was mapped,
page-faulted in and unmapped again. Measured on the four-wavelength PTFE likelihood (20 walkers x 7,296
geometries): 38.7 ms per call, 11.8 of them in the kernel; with the heap kept, 22.9 ms and none. An
explicit MALLOC_MMAP_THRESHOLD_ / MALLOC_TRIM_THRESHOLD_ is kept.

JAX in double precision: the forward model is JAX code, and polarization near the specular peak and
Fresnel reflectances of nearly index-matched media need float64 (float32 loses R ~ 1e-17 and DOP's
differences of nearly equal numbers). JAX's default is float32; spacepol switches it on for the process.

JAX's compiled programs kept on disk: every model structure and batch size is compiled once (0.2 s for the
paper's DOP likelihood, 1-2 s for a full-Mueller one), and without a cache every command compiles them
again. Kept in $SPACEPOL_CACHE_DIR, else $XDG_CACHE_HOME/spacepol/jax or ~/.cache/spacepol/jax (entries
of 0.1-1 MB, one per model structure and batch size; delete the folder at will); SPACEPOL_CACHE_DIR=""
turns it off. A cache folder that cannot be written only costs the compilations.
"""

import ctypes
import ctypes.util
import os
import sys

_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
_HEAP_KEPT_BYTES = 32 * 1024 * 1024  # glibc's largest allowed mmap threshold on 64-bit


def keep_heap() -> None:
    if not sys.platform.startswith("linux") or any(v in os.environ for v in ("MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_")):
        return
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        libc.mallopt(_M_MMAP_THRESHOLD, _HEAP_KEPT_BYTES)
        libc.mallopt(_M_TRIM_THRESHOLD, 4 * _HEAP_KEPT_BYTES)
    except (OSError, AttributeError):  # not glibc (musl, ...): nothing to tune
        return


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


def configure_jax() -> None:
    import jax

    jax.config.update("jax_enable_x64", True)
    folder = os.environ.get("SPACEPOL_CACHE_DIR")
    if folder is None:
        base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        folder = os.path.join(base, "spacepol", "jax")
    if not folder:
        return
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError:
        return
    if not os.access(folder, os.W_OK):
        return
    jax.config.update("jax_compilation_cache_dir", folder)
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
